"""Small meshes with known answers, built with numpy alone."""

import numpy as np

from autorig_addon.core.dataset.sample import CharacterSample
from autorig_addon.core.distances.grid import VoxelGrid
from autorig_addon.core.geometry.subdivision import subdivide_midpoints
from autorig_addon.core.procedural import generate_character
from autorig_addon.core.skeleton.posing import axis_angle_matrices, pose_matrices, posed_vertices
from autorig_addon.core.types import Mesh, Skeleton, Weights


def grid(nx: int, ny: int, size: float = 1.0) -> Mesh:
    """A flat (nx x ny)-vertex square grid in the z=0 plane, normals +z."""
    xs, ys = np.meshgrid(np.linspace(0, size, nx), np.linspace(0, size, ny), indexing="ij")
    V = np.stack([xs.ravel(), ys.ravel(), np.zeros(nx * ny)], axis=1)
    idx = np.arange(nx * ny).reshape(nx, ny)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()
    F = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])
    return Mesh(V, F)


def cylinder(radius: float = 0.1, height: float = 1.0, segments: int = 24, rings: int = 21,
             capped: bool = True, z0: float = 0.0, flip: bool = False) -> Mesh:
    """A cylinder along +z from ``z0`` to ``z0 + height``, outward normals
    (inward if ``flip``), optionally closed with fan caps."""
    angles = np.linspace(0, 2 * np.pi, segments, endpoint=False)
    zs = np.linspace(z0, z0 + height, rings)
    ring = np.stack([radius * np.cos(angles), radius * np.sin(angles)], axis=1)
    V = np.concatenate([np.column_stack([ring, np.full(segments, z)]) for z in zs])
    faces = []
    for r in range(rings - 1):
        for s in range(segments):
            a, b = r * segments + s, r * segments + (s + 1) % segments
            c, d = a + segments, b + segments
            faces += [[a, b, d], [a, d, c]]
    if capped:
        bottom, top = len(V), len(V) + 1
        V = np.vstack([V, [0, 0, z0], [0, 0, z0 + height]])
        last = (rings - 1) * segments
        for s in range(segments):
            faces.append([bottom, (s + 1) % segments, s])
            faces.append([top, last + s, last + (s + 1) % segments])
    F = np.asarray(faces)
    if flip:
        F = F[:, ::-1]
    return Mesh(V, F)


def triangle_and_flat_triangles(flat_count: int) -> Mesh:
    """One triangle of area 0.5 at z = 1, then ``flat_count`` triangles
    without area: consecutive points 0.1 apart on the x axis."""
    V = np.array([[0, 0, 1], [1, 0, 1], [0, 1, 1]] + [[0.1 * k, 0, 0] for k in range(flat_count + 2)], dtype=float)
    F = np.array([[0, 1, 2]] + [[3 + k, 4 + k, 5 + k] for k in range(flat_count)])
    return Mesh(V, F)


def subdivided(mesh: Mesh, times: int) -> Mesh:
    """``mesh`` with every triangle split in four ``times`` times (same
    shape, about four times the vertices each time), one object."""
    vertices, triangles = mesh.vertices, mesh.triangles
    for _ in range(times):
        vertices, triangles, _ = subdivide_midpoints(vertices, triangles, np.zeros((len(vertices), 0)))
    return Mesh(vertices, triangles, object_names=mesh.object_names[:1])


def two_bone_skeleton(height: float = 1.0) -> Skeleton:
    """Bone 'lower' from z=0 to z=h/2, 'upper' from h/2 to h."""
    return Skeleton(
        joints=[[0, 0, 0], [0, 0, height / 2]], parents=[-1, 0], names=("lower", "upper"),
        tails=[[0, 0, height / 2], [0, 0, height]],
    )


def two_bone_weights(mesh: Mesh, height: float = 1.0, blend: float = 0.2) -> Weights:
    """Weight of 'upper' rises linearly from 0 to 1 across ``z in [h/2 - blend/2, h/2 + blend/2]``."""
    z = mesh.vertices[:, 2]
    upper = np.clip((z - (height / 2 - blend / 2)) / blend, 0.0, 1.0)
    return Weights(np.stack([1 - upper, upper], axis=1), ("lower", "upper"))


def small_humanoid() -> Skeleton:
    """Hips, spine, head, two arms and two legs (joints j0..j8, z in [0.5, 1.8]);
    size 2 when scaled by 1."""
    joints = [
        [0.0, 0.0, 1.0],   # 0 hips
        [0.0, 0.0, 1.4],   # 1 chest
        [0.0, 0.0, 1.8],   # 2 head
        [0.3, 0.0, 1.4],   # 3 upper arm L
        [0.6, 0.0, 1.4],   # 4 forearm L
        [-0.3, 0.0, 1.4],  # 5 upper arm R
        [-0.6, 0.0, 1.4],  # 6 forearm R
        [0.1, 0.0, 0.5],   # 7 shin L
        [-0.1, 0.0, 0.5],  # 8 shin R
    ]
    parents = [-1, 0, 1, 1, 3, 1, 5, 0, 0]
    return Skeleton(np.asarray(joints), parents, tuple(f"j{k}" for k in range(len(parents))))


def arm_posed_humanoid(left_degrees: float, right_degrees: float, prefix: str = "mixamorig:") -> Skeleton:
    """A 1.7-high humanoid with Mixamo's bone names (after ``prefix``) whose
    arms hang the given angles below the horizontal, straight from the upper
    arm to the index finger's tip; hips at z = 1, feet on the ground, facing -Y."""
    joints, parents, names = [], [], []

    def add(name: str, point, parent: int) -> int:
        joints.append(point)
        parents.append(parent)
        names.append(prefix + name)
        return len(joints) - 1

    hips = add("Hips", [0.0, 0.0, 1.0], -1)
    spine = add("Spine", [0.0, 0.0, 1.2], hips)
    chest = add("Spine2", [0.0, 0.0, 1.4], spine)
    add("Head", [0.0, 0.0, 1.55], add("Neck", [0.0, 0.0, 1.5], chest))
    for side, sign, degrees in (("Left", 1.0, left_degrees), ("Right", -1.0, right_degrees)):
        shoulder = add(f"{side}Shoulder", [sign * 0.05, 0.0, 1.45], chest)
        start = np.array([sign * 0.15, 0.0, 1.45])
        along = np.array([sign * np.cos(np.radians(degrees)), 0.0, -np.sin(np.radians(degrees))])
        joint = add(f"{side}Arm", start, shoulder)
        for name, reach in (("ForeArm", 0.28), ("Hand", 0.52), ("HandIndex1", 0.6), ("HandIndex2", 0.64)):
            joint = add(f"{side}{name}", start + reach * along, joint)
        knee = add(f"{side}Leg", [sign * 0.1, 0.0, 0.5], add(f"{side}UpLeg", [sign * 0.1, 0.0, 0.95], hips))
        add(f"{side}ToeBase", [sign * 0.1, -0.12, 0.0], add(f"{side}Foot", [sign * 0.1, 0.0, 0.08], knee))
    return Skeleton(np.asarray(joints), parents, tuple(names))


def points_along_bones(skeleton: Skeleton, per_bone: int = 12, offset: float = 0.01) -> tuple[Mesh, np.ndarray]:
    """A point cloud of ``per_bone`` points along each bone, ``offset`` off
    its axis, as a Mesh (one triangle) and the (n,) bone index of each point."""
    points, owners = [], []
    for bone, (head, tail) in enumerate(zip(skeleton.joints, skeleton.tails)):
        for t in np.linspace(0.1, 0.9, per_bone):
            points.append(head + t * (tail - head) + [offset, offset, 0.0])
            owners.append(bone)
    return Mesh(np.asarray(points), [[0, 1, 2]]), np.asarray(owners)


def box_mesh(low, high, spacing: float) -> Mesh:
    """Closed axis-aligned box whose faces are grids of about ``spacing``,
    outward normals (faces are not welded to each other; the surface is
    still closed)."""
    low, high = np.asarray(low, float), np.asarray(high, float)
    vertices, triangles = [], []
    for axis in range(3):
        u, w = (axis + 1) % 3, (axis + 2) % 3
        nu = max(1, int(np.ceil((high[u] - low[u]) / spacing)))
        nw = max(1, int(np.ceil((high[w] - low[w]) / spacing)))
        su, sw = np.meshgrid(np.linspace(low[u], high[u], nu + 1), np.linspace(low[w], high[w], nw + 1), indexing="ij")
        for level, flip in ((low[axis], True), (high[axis], False)):
            grid_points = np.zeros((su.size, 3))
            grid_points[:, axis], grid_points[:, u], grid_points[:, w] = level, su.ravel(), sw.ravel()
            index = np.arange(su.size).reshape(su.shape) + sum(len(v) for v in vertices)
            a, b = index[:-1, :-1].ravel(), index[1:, :-1].ravel()
            c, d = index[1:, 1:].ravel(), index[:-1, 1:].ravel()
            faces = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])
            triangles.append(faces[:, ::-1] if flip else faces)
            vertices.append(grid_points)
    return Mesh(np.concatenate(vertices), np.concatenate(triangles))


def plain_grid(shape, cell_size: float = 1.0, surface=None, inside=None) -> VoxelGrid:
    """A voxel grid with its origin at 0 and the given masks (default all False)."""
    empty = np.zeros(shape, dtype=bool)
    return VoxelGrid(
        np.zeros(3), cell_size, tuple(shape),
        empty.copy() if surface is None else surface,
        empty.copy() if inside is None else inside,
    )


def vertex_index(mesh: Mesh, point) -> int:
    """Index of the vertex of ``mesh`` at ``point`` (which must be one)."""
    index = int(np.argmin(np.linalg.norm(mesh.vertices - np.asarray(point, float), axis=1)))
    assert np.allclose(mesh.vertices[index], point), "the fixture has no vertex there"
    return index


def body_with_hat():
    """A closed cylinder body (r 0.2, z in [0, 1]) with two bones up its axis,
    and a box hat 0.15 above its top that touches nothing.

    Returns
    -------
    mesh : Mesh, the body's vertices first
    hat_vertices : (k,) int array, the hat's rows of ``mesh``
    heads, tails : (2, 3) float arrays: the lower bone z 0.05 to 0.6, the upper 0.6 to 0.95
    """
    body = cylinder(radius=0.2, height=1.0, segments=32, rings=21)
    hat = box_mesh([-0.15, -0.15, 1.1], [0.15, 0.15, 1.3], 0.05)
    mesh = Mesh.concatenate([body, hat])
    heads = np.array([[0, 0, 0.05], [0, 0, 0.6]])
    tails = np.array([[0, 0, 0.6], [0, 0, 0.95]])
    return mesh, np.arange(body.vertex_count, mesh.vertex_count), heads, tails


def procedural_sample(seed: int) -> CharacterSample:
    """The procedural character of ``seed``, normalised as a cached sample
    (seed 4: a 40-bone chain of 1,086 vertices; seed 5: 30 bones, 762
    vertices)."""
    character = generate_character(seed)
    return CharacterSample.from_character(f"procedural_{seed}", character.kind, character.mesh, character.skeleton,
                                          character.weights)


def procedural_of_kind(kind: str, seed: int = 0):
    """(normalised sample, generated character) of a procedural ``kind`` (``biped``, ``quadruped``, ``fish`` ...)."""
    character = generate_character(seed, kind)
    sample = CharacterSample.from_character(f"procedural/{kind}_{seed}", character.kind, character.mesh,
                                            character.skeleton, character.weights)
    return sample, character


def random_skin_inputs(seed: int, vertex_count: int, bone_count: int):
    """Random inputs of ``features.skin_graph``: points in the unit cube with
    random triangles among all but the last vertex (which has no mesh edge),
    a random tree of ``bone_count`` bones, distances in [0.01, 1] and a prior
    whose rows sum to 1 with about half the entries 0.

    Returns
    -------
    mesh, skeleton, distances (n, b), prior (n, b)
    """
    rng = np.random.default_rng(seed)
    vertices = rng.uniform(0.0, 1.0, (vertex_count, 3))
    triangles = np.array([rng.choice(vertex_count - 1, 3, replace=False) for _ in range(vertex_count)])
    parents = [-1] + [int(rng.integers(0, bone)) for bone in range(1, bone_count)]
    skeleton = Skeleton(rng.uniform(0.0, 1.0, (bone_count, 3)), parents, tuple(f"b{k}" for k in range(bone_count)),
                        rng.uniform(0.0, 1.0, (bone_count, 3)))
    distances = rng.uniform(0.01, 1.0, (vertex_count, bone_count))
    prior = rng.uniform(0.0, 1.0, (vertex_count, bone_count)) * (rng.random((vertex_count, bone_count)) < 0.5)
    prior[np.arange(vertex_count), distances.argmin(axis=1)] += 0.1
    return Mesh(vertices, triangles), skeleton, distances, prior / prior.sum(axis=1, keepdims=True)


#: (heads, tails, exact message) of bones every vertex-to-bone distance refuses.
BAD_BONES = [
    (np.zeros((0, 3)), np.zeros((0, 3)), "No bones were given; add deforming bones to the armature."),
    ([[np.nan, 0, 0]], [[0, 0, 1]], "A bone has a NaN or infinite position; fix the armature first."),
    ([[0, 0, 0]], [[0, 0, np.inf]], "A bone has a NaN or infinite position; fix the armature first."),
    (np.zeros((2, 3)), np.ones((1, 3)), "Every bone needs one head and one tail."),
]


def card_strip(top, bottom, width: float, segments: int = 2, two_sided: bool = False) -> Mesh:
    """A hair card: an open strip ``width`` wide from ``top`` to ``bottom``,
    ``segments`` quads long, its width along x; ``two_sided``: every face
    also wound the other way on the same vertices (closed, no volume)."""
    top, bottom = np.asarray(top, float), np.asarray(bottom, float)
    centres = top + np.linspace(0.0, 1.0, segments + 1)[:, None] * (bottom - top)
    half = np.array([width / 2, 0.0, 0.0])
    vertices = np.stack([centres - half, centres + half], axis=1).reshape(-1, 3)
    left, right = np.arange(segments) * 2, np.arange(segments) * 2 + 1
    triangles = np.concatenate([np.stack([left, right, right + 2], 1), np.stack([left, right + 2, left + 2], 1)])
    if two_sided:
        triangles = np.concatenate([triangles, triangles[:, ::-1]])
    return Mesh(vertices, triangles)


def procedural_biped_with(*objects) -> Mesh:
    """The procedural biped of seed 0 (right hand near x -0.28, z 0.57), object ``Biped``, with
    ``objects`` ((name, Mesh) pairs) after it as objects of their own."""
    character = generate_character(0, "biped")
    body = Mesh(character.mesh.vertices, character.mesh.triangles, object_names=("Biped",))
    return Mesh.concatenate([body, *(Mesh(mesh.vertices, mesh.triangles, object_names=(name,))
                                     for name, mesh in objects)])


def procedural_biped_posed(turns: dict) -> tuple[Mesh, dict]:
    """The procedural biped of seed 0 posed by its own weights: ``turns`` maps
    deform bone names to (axis, degrees) turns about their heads. Returns the
    posed mesh (object ``Biped``) and the posed heads of every deform bone by name."""
    character = generate_character(0, "biped")
    deform = character.skeleton.deform_subset()
    rotations = np.tile(np.eye(3), (deform.bone_count, 1, 1))
    for bone, (axis, degrees) in turns.items():
        rotations[deform.names.index(bone)] = axis_angle_matrices(np.array([axis], dtype=float),
                                                                  np.radians([degrees]))[0]
    weights = character.weights.select_bones(deform.names).matrix
    posed = posed_vertices(character.mesh.vertices, weights, character.skeleton, rotations[None])[0]
    matrices = pose_matrices(character.skeleton, rotations)
    heads = np.einsum("bij,bj->bi", matrices[:, :3, :3], deform.joints) + matrices[:, :3, 3]
    return (Mesh(posed, character.mesh.triangles, object_names=("Biped",)),
            dict(zip(deform.names, heads)))
