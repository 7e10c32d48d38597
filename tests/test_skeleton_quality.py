"""The checks that tell a poor skeleton before success is reported (core/rigging/quality.py)."""

import numpy as np

from autorig_addon.core.rigging.quality import FAR_FROM_SURFACE, enclosed_by, skeleton_problems
from autorig_addon.core.types import Mesh, Skeleton
from geometry_fixtures import box_mesh

#: A body: the box |x| <= 0.2, |y| <= 0.1, 0 <= z <= 1, its surface sampled on a grid (points, no triangles).
LOW, HIGH = np.array([-0.2, -0.1, 0.0]), np.array([0.2, 0.1, 1.0])
GRID = np.stack(np.meshgrid(*[np.linspace(a, b, 9) for a, b in zip(LOW, HIGH)], indexing="ij"), -1).reshape(-1, 3)
SURFACE = Mesh(GRID[np.any(np.isclose(GRID, LOW) | np.isclose(GRID, HIGH), axis=1)], np.zeros((0, 3)))


def depth(points):
    inside = np.all((points >= LOW) & (points <= HIGH), axis=1)
    return np.where(inside, np.min(np.minimum(points - LOW, HIGH - points), axis=1), 0.0)


def biped(**moved):
    """A stick biped inside the box; ``moved`` replaces joints by name."""
    joints = {"spine": [0, 0, 0.5], "spine.001": [0, 0, 0.7], "neck": [0, 0, 0.85], "head": [0, 0, 0.9],
              "upper_arm.L": [0.1, 0, 0.8], "upper_arm.R": [-0.1, 0, 0.8], "thigh.L": [0.08, 0, 0.45],
              "thigh.R": [-0.08, 0, 0.45], "shin.L": [0.08, 0, 0.25], "shin.R": [-0.08, 0, 0.25]}
    parents = {"spine": None, "spine.001": "spine", "neck": "spine.001", "head": "neck", "upper_arm.L": "spine.001",
               "upper_arm.R": "spine.001", "thigh.L": "spine", "thigh.R": "spine", "shin.L": "thigh.L",
               "shin.R": "thigh.R"}
    parents.update({name: parent for name, (_, parent) in moved.items()})
    joints.update({name: point for name, (point, _) in moved.items()})
    names = list(joints)
    return Skeleton(np.array([joints[n] for n in names], float),
                    np.array([-1 if parents[n] is None else names.index(parents[n]) for n in names]), tuple(names))


def test_a_sound_biped_has_no_problem():
    assert skeleton_problems(biped(), depth, SURFACE) == ()


def test_a_bone_to_a_point_far_from_the_body_is_named():
    # A sword tip mirrored into the air: the forearm runs 1 unit out of the body.
    skeleton = biped(**{"forearm.L": ([1.1, 0, 0.8], "upper_arm.L")})
    assert skeleton_problems(skeleton, depth, SURFACE) == ("upper_arm.L lies mostly outside the body",)
    # Just outside the surface (within FAR_FROM_SURFACE, an open shell's thickness) is not outside.
    near = biped(**{"forearm.L": ([0.2 + FAR_FROM_SURFACE / 2, 0, 0.8], "upper_arm.L")})
    assert skeleton_problems(near, depth, SURFACE) == ()


def test_two_trees_a_long_bone_and_misplaced_limbs_are_named():
    two_trees = biped(**{"thigh.L": ([0.08, 0, 0.45], None)})
    assert "the skeleton is 2 separate trees, not one" in skeleton_problems(two_trees, depth, SURFACE)
    long = Skeleton(np.array([[0.0, 0, 0.0]]), np.array([-1]), ("root",), np.array([[0.0, 0, 1.2]]))
    assert skeleton_problems(long, lambda p: np.ones(len(p)), SURFACE) == ("root is longer than the body",)
    # The Mannequin of the issue: legs hanging from the chest.
    legs_from_chest = biped(**{"thigh.L": ([0.08, 0, 0.45], "spine.001"), "thigh.R": ([-0.08, 0, 0.45], "spine.001")})
    assert skeleton_problems(legs_from_chest, depth, SURFACE) == ("the legs do not hang from the hips",)
    arms_from_hips = biped(**{"upper_arm.L": ([0.1, 0, 0.8], "spine"), "upper_arm.R": ([-0.1, 0, 0.8], "spine")})
    assert skeleton_problems(arms_from_hips, depth, SURFACE) == (
        "the arms do not hang from the spine above the hips",)
    head_down = biped(**{"head": ([0, 0, 0.3], "neck")})
    assert "the head is not above the hips" in skeleton_problems(head_down, depth, SURFACE)


def test_bones_inside_an_open_mesh_whose_solid_is_a_shell_are_inside_the_body():
    """A 0 A.D. animal's mesh has holes, so its voxel solid leaked to its shell: no depth anywhere inside. A
    bone along the middle of such a body (a box 0.8 across without its top, the bone 0.4 from every wall,
    farther than FAR_FROM_SURFACE) read with the solid alone lies outside; its surface still encloses it
    (winding number 5/6 at the centre), so with ``enclosed`` it is inside. A bone leaving the box stays outside."""
    box = box_mesh((-0.4, -0.4, 0.0), (0.4, 0.4, 1.0), 0.1)
    open_top = box.triangles[~(box.vertices[box.triangles][:, :, 2] > 0.999).all(axis=1)]
    surface = Mesh(box.vertices, open_top)
    spine = Skeleton(np.array([[0.0, 0, 0.2], [0.0, 0, 0.5], [0.0, 0, 0.8]]), np.array([-1, 0, 1]),
                     ("spine", "spine.001", "spine.002"))
    shell = lambda points: np.zeros(len(points))  # noqa: E731
    assert 0.4 > FAR_FROM_SURFACE
    assert skeleton_problems(spine, shell, surface) == ("spine, spine.001 lie mostly outside the body",)
    assert skeleton_problems(spine, shell, surface, enclosed_by(surface)) == ()
    leaving = Skeleton(np.array([[0.3, 0, 0.5], [1.25, 0, 0.5]]), np.array([-1, 0]), ("root", "tip"))
    assert skeleton_problems(leaving, shell, surface, enclosed_by(surface)) == (
        "root lies mostly outside the body",)


def test_a_bone_along_a_big_face_of_a_low_poly_body_is_on_it():
    """The 0 A.D. rabbit: 111 vertices, so a front leg running just outside a face lies 0.1 of the body from
    every corner though 0.02 from the face. The distance that counts is the surface's (its triangles'): within
    FAR_FROM_SURFACE of them the leg is on the body; the same leg 0.15 out is not."""
    slab = box_mesh((-0.5, -0.5, 0.0), (0.5, 0.5, 0.1), 1.0)
    shell = lambda points: np.zeros(len(points))  # noqa: E731
    along = Skeleton(np.array([[-0.2, 0.0, 0.12], [0.2, 0.0, 0.12]]), np.array([-1, 0]), ("front_thigh.L", "shin"))
    # Every point along the leg is farther than FAR_FROM_SURFACE from the slab's corners, 0.02 from its top.
    corners = np.linalg.norm(np.linspace(along.joints[0], along.joints[1], 11)[:, None] - slab.vertices, axis=2)
    assert corners.min() > FAR_FROM_SURFACE
    assert skeleton_problems(along, shell, slab) == ()
    assert skeleton_problems(along, shell, Mesh(slab.vertices, np.zeros((0, 3)))) == (
        "front_thigh.L lies mostly outside the body",)
    lifted = Skeleton(along.joints + [0.0, 0.0, 0.15], along.parents, along.names)
    assert skeleton_problems(lifted, shell, slab) == ("front_thigh.L lies mostly outside the body",)
