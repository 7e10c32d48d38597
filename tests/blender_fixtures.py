"""Scenes built in code for the Blender-layer tests.

The reference scene: a two-bone armature standing on the origin (bone
``Lower`` from z=0 to z=1, ``Upper`` from z=1 to z=2), a closed cylinder
``Body`` (radius 0.3) skinned to it with known weights, and ``Sleeve``, an
open cylinder of radius 0.33 (10% looser) around the body with a small box
(the "button") floating off its side as a separate connected part.
"""

from __future__ import annotations

from dataclasses import dataclass

import bpy
import numpy as np

BODY_RADIUS = 0.3
BODY_HEIGHT = 2.0
SLEEVE_RADIUS = 1.1 * BODY_RADIUS
SLEEVE_Z_RANGE = (0.2, 1.8)
#: The body's weights blend linearly from Lower to Upper between these heights.
BLEND_START, BLEND_END = 0.8, 1.2
LOWER_BONE, UPPER_BONE = "Lower", "Upper"
#: Centre and half size of the button box, well outside the match distance.
BUTTON_CENTER = (0.5, 0.0, 0.4)
BUTTON_HALF_SIZE = 0.03


@dataclass
class RigScene:
    armature: object
    body: object
    sleeve: object
    sleeve_ring_vertex_count: int
    button_vertex_count: int


def reset_scene() -> None:
    bpy.ops.wm.read_factory_settings(use_empty=True)


def cylinder_geometry(radius: float, z_min: float, z_max: float, segments: int, rings: int, capped: bool):
    """Vertices (n, 3) and outward-facing faces of a cylinder along z.

    Side vertices come ring by ring from ``z_min`` up; with ``capped`` the
    bottom and top centre vertices follow and triangle fans close the ends.
    """
    angles = np.linspace(0.0, 2.0 * np.pi, segments, endpoint=False)
    heights = np.linspace(z_min, z_max, rings + 1)
    ring = np.stack([radius * np.cos(angles), radius * np.sin(angles)], axis=1)
    vertices = np.concatenate([np.column_stack([ring, np.full(segments, z)]) for z in heights])
    faces = []
    for r in range(rings):
        for s in range(segments):
            a, b = r * segments + s, r * segments + (s + 1) % segments
            faces.append((a, b, b + segments, a + segments))
    if capped:
        bottom, top = len(vertices), len(vertices) + 1
        vertices = np.vstack([vertices, [0.0, 0.0, z_min], [0.0, 0.0, z_max]])
        last = rings * segments
        for s in range(segments):
            faces.append((bottom, (s + 1) % segments, s))
            faces.append((top, last + s, last + (s + 1) % segments))
    return vertices, faces


def box_geometry(center, half_size: float, index_offset: int = 0):
    """Vertices (8, 3) and the 6 outward quads of an axis-aligned cube."""
    corners = np.array([[x, y, z] for z in (-1, 1) for y in (-1, 1) for x in (-1, 1)], dtype=float)
    vertices = np.asarray(center, dtype=float) + half_size * corners
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    return vertices, [tuple(i + index_offset for i in quad) for quad in quads]


def mesh_object(name: str, vertices, faces, edges=()) -> bpy.types.Object:
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(np.asarray(vertices, dtype=float).tolist(), list(edges), [list(f) for f in faces])
    mesh.update()
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def make_armature(name: str = "Armature", deform_upper: bool = True) -> bpy.types.Object:
    """Two connected bones up the z axis: Lower (0 to 1), Upper (1 to 2)."""
    data = bpy.data.armatures.new(name)
    obj = bpy.data.objects.new(name, data)
    bpy.context.scene.collection.objects.link(obj)
    bpy.context.view_layer.objects.active = obj
    bpy.ops.object.mode_set(mode="EDIT")
    lower = data.edit_bones.new(LOWER_BONE)
    lower.head, lower.tail = (0.0, 0.0, 0.0), (0.0, 0.0, 1.0)
    upper = data.edit_bones.new(UPPER_BONE)
    upper.head, upper.tail = (0.0, 0.0, 1.0), (0.0, 0.0, 2.0)
    upper.parent = lower
    upper.use_connect = True
    upper.use_deform = deform_upper
    bpy.ops.object.mode_set(mode="OBJECT")
    return obj


#: How closely a transferred sleeve follows the body's blend: the transfer's
#: default surface smoothing (``core.transfer.options.DEFAULT_SMOOTHING_LENGTH``)
#: rounds the blend's kinks at ``BLEND_START`` and ``BLEND_END`` by up to 0.3 %.
COPY_TOLERANCE = 5e-3


def expected_body_weights(z: np.ndarray) -> np.ndarray:
    """(n, 2) weights (Lower, Upper) of the body at heights ``z``."""
    upper = np.clip((np.asarray(z) - BLEND_START) / (BLEND_END - BLEND_START), 0.0, 1.0)
    return np.column_stack([1.0 - upper, upper])


def add_weights(obj, names, weights: np.ndarray) -> None:
    """Vertex groups ``names`` filled from the (n, k) ``weights`` (zeros skipped)."""
    for column, name in enumerate(names):
        group = obj.vertex_groups.get(name) or obj.vertex_groups.new(name=name)
        for index in np.flatnonzero(weights[:, column] > 0):
            group.add([int(index)], float(weights[index, column]), "REPLACE")


def bind(obj, armature) -> None:
    modifier = obj.modifiers.new("Armature", "ARMATURE")
    modifier.object = armature
    obj.parent = armature


def make_body(armature, segments: int = 24, rings: int = 20) -> bpy.types.Object:
    vertices, faces = cylinder_geometry(BODY_RADIUS, 0.0, BODY_HEIGHT, segments, rings, capped=True)
    body = mesh_object("Body", vertices, faces)
    add_weights(body, [LOWER_BONE, UPPER_BONE], expected_body_weights(vertices[:, 2]))
    bind(body, armature)
    return body


def make_sleeve(segments: int = 32, rings: int = 16, with_button: bool = True) -> tuple:
    """The sleeve object, its number of tube vertices and of button vertices."""
    vertices, faces = cylinder_geometry(SLEEVE_RADIUS, *SLEEVE_Z_RANGE, segments, rings, capped=False)
    tube_count = len(vertices)
    button_count = 0
    if with_button:
        box_vertices, box_faces = box_geometry(BUTTON_CENTER, BUTTON_HALF_SIZE, index_offset=tube_count)
        vertices = np.vstack([vertices, box_vertices])
        faces = faces + box_faces
        button_count = len(box_vertices)
    return mesh_object("Sleeve", vertices, faces), tube_count, button_count


def build_rig_scene(with_button: bool = True) -> RigScene:
    """Armature, skinned body and unweighted sleeve in the current (empty) scene."""
    armature = make_armature()
    body = make_body(armature)
    sleeve, tube_count, button_count = make_sleeve(with_button=with_button)
    bpy.context.view_layer.update()
    return RigScene(armature, body, sleeve, tube_count, button_count)


def select_only(objects, active=None) -> None:
    for obj in bpy.context.view_layer.objects:
        obj.select_set(obj in objects)
    bpy.context.view_layer.objects.active = active


def local_positions(obj) -> np.ndarray:
    """(n, 3) float64 local vertex positions."""
    values = np.empty(len(obj.data.vertices) * 3, dtype=np.float32)
    obj.data.vertices.foreach_get("co", values)
    return values.reshape(-1, 3).astype(np.float64)


def group_weights(obj, names) -> np.ndarray:
    """(n, k) float64 weights of the named groups (independent of the add-on's reader)."""
    matrix = np.zeros((len(obj.data.vertices), len(names)))
    for column, name in enumerate(names):
        group = obj.vertex_groups.get(name)
        if group is None:
            continue
        for vertex in obj.data.vertices:
            for element in vertex.groups:
                if element.group == group.index:
                    matrix[vertex.index, column] = element.weight
    return matrix


def scene_state(objects) -> dict:
    """A comparable summary of everything the transfer may change on ``objects``
    (plus the list of all objects, so nothing may be created either)."""
    state = {"objects": sorted(obj.name for obj in bpy.data.objects)}
    for obj in objects:
        entry = {
            "modifiers": [(m.name, m.type, getattr(m, "object", None) and m.object.name) for m in obj.modifiers],
            "parent": obj.parent.name if obj.parent else None,
            "matrix_world": [list(row) for row in obj.matrix_world],
            "mode": obj.mode,
        }
        if obj.type == "MESH":
            names = [group.name for group in obj.vertex_groups]
            entry["groups"] = names
            entry["weights"] = group_weights(obj, names).round(6).tolist()
            entry["attributes"] = sorted(a.name for a in obj.data.attributes)
        elif obj.type == "ARMATURE":
            entry["bones"] = [(b.name, b.use_deform) for b in obj.data.bones]
        state[obj.name] = entry
    return state


class RecordingWindowManager:
    """Stands in for bpy.types.WindowManager where a test calls an
    operator's progress and timer code directly: records every call."""

    def __init__(self):
        self.calls = []

    def progress_begin(self, low, high):
        self.calls.append(("begin", low, high))

    def progress_update(self, value):
        self.calls.append(("update", value))

    def progress_end(self):
        self.calls.append(("end",))

    def event_timer_remove(self, timer):
        self.calls.append(("remove_timer", timer))


class RecordingWorkspace:
    """Stands in for bpy.types.WorkSpace: records each status text set (None clears it)."""

    def __init__(self):
        self.texts = []

    def status_text_set(self, text):
        self.texts.append(text)


def parent_to_bone(obj, armature, bone_name: str) -> None:
    """Parent ``obj`` to one bone as a user does: the object selected, the
    armature active in Pose Mode with the bone active, Ctrl+P > Bone."""
    select_only([obj, armature], active=armature)
    bpy.ops.object.mode_set(mode="POSE")
    armature.data.bones.active = armature.data.bones[bone_name]
    bpy.ops.object.parent_set(type="BONE", keep_transform=True)
    bpy.ops.object.mode_set(mode="OBJECT")
    bpy.context.view_layer.update()


def pose_bone_turned(armature, bone_name: str, degrees: float, axis: str = "X") -> None:
    """Turn one pose bone by ``degrees`` about its own ``axis`` (all others at rest)."""
    from mathutils import Quaternion, Vector

    for pose_bone in armature.pose.bones:
        pose_bone.rotation_mode = "QUATERNION"
        pose_bone.rotation_quaternion = (1.0, 0.0, 0.0, 0.0)
    axis_vector = Vector({"X": (1, 0, 0), "Y": (0, 1, 0), "Z": (0, 0, 1)}[axis])
    armature.pose.bones[bone_name].rotation_quaternion = Quaternion(axis_vector, np.radians(degrees))
    bpy.context.view_layer.update()


def evaluated_world_vertices(obj) -> np.ndarray:
    """(n, 3) world positions of ``obj``'s vertices after its modifiers and parents."""
    depsgraph = bpy.context.evaluated_depsgraph_get()
    evaluated = obj.evaluated_get(depsgraph)
    mesh = evaluated.to_mesh()
    try:
        values = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
        mesh.vertices.foreach_get("co", values)
        matrix = np.array(evaluated.matrix_world)
    finally:
        evaluated.to_mesh_clear()
    points = values.reshape(-1, 3).astype(np.float64)
    return points @ matrix[:3, :3].T + matrix[:3, 3]


#: The procedural biped the rig tests use: symmetric, 0.94 tall, 0.6 wide with its arms out.
BIPED_SEED = 0


def armatures() -> list:
    """Every armature object of the file."""
    return [obj for obj in bpy.data.objects if obj.type == "ARMATURE"]


def add_biped(name: str = "Biped", location=(0.0, 0.0, 0.0)) -> bpy.types.Object:
    """The procedural biped of :data:`BIPED_SEED` as a mesh object at ``location``."""
    from autorig_addon.core.procedural import generate_character

    mesh = generate_character(BIPED_SEED, "biped").mesh
    obj = mesh_object(name, mesh.vertices, mesh.triangles)
    obj.location = location
    bpy.context.view_layer.update()
    return obj

