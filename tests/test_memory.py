"""Free memory, and refusing voxel resolutions that would not fit before they run."""

import re

import numpy as np
import pytest

from autorig_addon.core import memory
from autorig_addon.core.distances import bone_distances as pipeline
from autorig_addon.core.distances.grid import DEFAULT_RESOLUTION
from autorig_addon.core.distances.hollow_dist import hollow_distances
from autorig_addon.core.distances.memory_estimate import (
    FIXED_BYTES,
    GEODESIC_MEMORY,
    HOLLOW_MEMORY,
    SURFACE_CELLS_PER_AREA,
    check_voxel_memory,
    estimated_memory_bytes,
    largest_fitting_resolution,
    mesh_area,
)
from autorig_addon.core.distances.surface_voxels import voxelize_surface
from autorig_addon.core.errors import InputError
from autorig_addon.core.skinning.geometric import geometric_weights
from geometry_fixtures import box_mesh, cylinder, small_humanoid

GIB = 2**30


def free_memory(monkeypatch, size):
    """Pretend the machine has ``size`` bytes free."""
    monkeypatch.setattr(memory, "available_memory_bytes", lambda: size)


def test_available_memory_is_read_from_meminfo(tmp_path, monkeypatch):
    meminfo = tmp_path / "meminfo"
    meminfo.write_text("MemTotal:       32000000 kB\nMemFree:         1000000 kB\nMemAvailable:   20000000 kB\n")
    monkeypatch.setattr(memory, "MEMINFO_PATH", str(meminfo))
    assert memory.available_memory_bytes() == 20000000 * 1024
    assert memory.usable_memory_bytes() == int(0.8 * 20000000 * 1024)
    monkeypatch.setattr(memory, "MEMINFO_PATH", str(tmp_path / "missing"))
    assert memory.available_memory_bytes() > 0  # os.sysconf's answer on this machine


def test_require_memory_refuses_only_beyond_the_usable_share(monkeypatch):
    free_memory(monkeypatch, 10 * GIB)
    memory.require_memory(8 * GIB, "A job", "Do less.")  # exactly the usable 80 %
    with pytest.raises(InputError, match=re.escape(
            "A job would need about 8.5 GiB of memory, but only 10 GiB is free. Do less.")):
        memory.require_memory(8.5 * GIB, "A job", "Do less.")
    free_memory(monkeypatch, None)  # a system that does not say: never refused
    memory.require_memory(1e18, "A job", "Do less.")


def test_estimate_counts_cells_surface_vertices_and_bones():
    # A closed 1 x 1 x 2 box (area 10) with one bone inside: at resolution 64
    # the grid is 32 x 32 x 64 cells plus 2 cells of padding a side.
    box = box_mesh([0, 0, 0], [1, 1, 2], 0.25)
    heads, tails = np.array([[0.5, 0.5, 0.2]]), np.array([[0.5, 0.5, 1.8]])
    assert mesh_area(box) == pytest.approx(10.0)
    cells = 36 * 36 * 68
    surface = SURFACE_CELLS_PER_AREA * 10.0 / (2.0 / 64) ** 2
    expected = (FIXED_BYTES + HOLLOW_MEMORY.per_cell * cells + HOLLOW_MEMORY.per_surface_cell * surface
                + HOLLOW_MEMORY.per_vertex * box.vertex_count + HOLLOW_MEMORY.per_vertex_bone * box.vertex_count)
    assert estimated_memory_bytes(box, heads, tails, 64) == pytest.approx(expected, rel=1e-12)
    assert voxelize_surface(box, 64, cover_points=np.vstack([heads, tails])).shape == (36, 36, 68)
    assert estimated_memory_bytes(box, heads, tails, 64, GEODESIC_MEMORY) < expected


def test_surface_cells_follow_the_area_on_a_curved_surface():
    # (The faces of an axis-aligned box lie on cell boundaries and touch two
    # layers; characters are curved.)
    tube = cylinder(radius=0.3, height=2.0, segments=96, rings=61)
    for resolution in (64, 128):
        grid = voxelize_surface(tube, resolution)
        estimate = SURFACE_CELLS_PER_AREA * mesh_area(tube) / grid.cell_size ** 2
        assert 0.85 * estimate < grid.surface.sum() < estimate


def test_largest_fitting_resolution_is_the_last_that_fits():
    box = box_mesh([0, 0, 0], [1, 1, 2], 0.25)
    heads, tails = np.array([[0.5, 0.5, 0.2]]), np.array([[0.5, 0.5, 1.8]])
    budget = estimated_memory_bytes(box, heads, tails, 300)
    assert largest_fitting_resolution(box, heads, tails, 1024, budget) == 300
    assert largest_fitting_resolution(box, heads, tails, 200, budget) == 200
    assert largest_fitting_resolution(box, heads, tails, 1024, 1.0) is None


def test_skinning_at_a_resolution_that_does_not_fit_is_refused_before_voxelising(monkeypatch):
    box = box_mesh([-0.3, -0.2, 0.4], [0.3, 0.2, 1.9], 0.1)
    skeleton = small_humanoid()
    deform = skeleton.deform_subset()
    free_memory(monkeypatch, 2 * GIB)
    fitting = largest_fitting_resolution(box, deform.joints, deform.tails, 1024, 0.8 * 2 * GIB)
    needed = estimated_memory_bytes(box, deform.joints, deform.tails, 1024)
    assert 300 < fitting < 1024 and needed > 10 * GIB

    def never(*arguments, **keywords):
        raise AssertionError("the grid was allocated")

    monkeypatch.setattr(pipeline, "voxelize_covering_bones", never)
    message = (f"would need about {memory.format_bytes(needed)} of memory, but only 2 GiB is free. "
               f"Resolution {fitting} fits: lower it to that or less (Resolution in the Skin panel, "
               "--resolution on the command line).")
    with pytest.raises(InputError, match=r"^The voxel grid at resolution 1024 \(\d+ x \d+ x \d+ cells\) "
                                         + re.escape(message) + "$"):
        geometric_weights(box, skeleton, resolution=1024)
    with pytest.raises(InputError, match=re.escape(message)):
        hollow_distances(box, deform.joints, deform.tails, resolution=1024)
    # The default resolution fits and is not checked against anything else.
    check_voxel_memory(box, deform.joints, deform.tails, DEFAULT_RESOLUTION)
    free_memory(monkeypatch, 1)
    with pytest.raises(InputError, match=re.escape("Free some memory (close other programs) or simplify the mesh.")):
        check_voxel_memory(box, deform.joints, deform.tails, DEFAULT_RESOLUTION)
