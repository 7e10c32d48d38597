"""The artist's own vertex groups that share a name with a bone being weighted.

Skinning writes one vertex group per deform bone, named after it. A mesh
may already hold a group of that name that is no binding's: a mask, a
selection set, weights painted for something else (``spine``,
``thigh.L``). Overwriting it would lose the artist's data without a word.
Such a group is kept, renamed ``spine.artist`` (``.artist.001`` ... when
taken), and everything of the mesh that used it by name follows it: its
modifiers (a Mask, a Displace), its shape keys' vertex groups, its particle
systems, and other objects' constraints aimed at it.

A group is a binding's when an armature the mesh already follows has a
bone of its name (:func:`.armature_binding.armature_bindings`): skinning
again to that armature, or to another that replaces it, rightly replaces
it. Replace Binding removes the old binding's groups before (``unbind``);
*Replace All Groups* removes every group, and renames none.
"""

from __future__ import annotations

from contextlib import contextmanager
from typing import Iterable

import bpy

from ..core.messages import listed_names
from .armature_binding import armature_bindings

#: Added to an artist's group's name to keep it beside the bone's group.
ARTIST_SUFFIX = ".artist"
#: Blender cuts vertex group names to this many bytes.
MAX_GROUP_NAME_BYTES = 63


def artist_group_renames(obj, written: Iterable[str], armature) -> dict[str, str]:
    """{group name: new name} for each vertex group of ``obj`` named after a
    bone in ``written`` (the groups a skinning run fills) that is no binding's
    (module docstring). New names clash with no group of ``obj`` and no bone
    of ``armature``."""
    written = set(written)
    binding_bones = {bone.name for binding in armature_bindings(obj) for bone in binding.armature.data.bones}
    artist = [group.name for group in obj.vertex_groups if group.name in written and group.name not in binding_bones]
    taken = {group.name for group in obj.vertex_groups} | {bone.name for bone in armature.data.bones}
    renames = {}
    for name in artist:
        renames[name] = _free_name(name, taken)
        taken.add(renames[name])
    return renames


def _free_name(name: str, taken: set) -> str:
    number = 0
    while True:
        suffix = ARTIST_SUFFIX + (f".{number:03d}" if number else "")
        base = name.encode()[:MAX_GROUP_NAME_BYTES - len(suffix.encode())].decode(errors="ignore")
        candidate = base + suffix
        if candidate not in taken:
            return candidate
        number += 1


def renames_note(obj_name: str, renames: dict) -> str:
    """What the report says about ``renames`` of one mesh."""
    old, new = listed_names(list(renames), quoted=True), listed_names(list(renames.values()), quoted=True)
    groups = "vertex group" if len(renames) == 1 else "vertex groups"
    return f"'{obj_name}': its own {groups} {old} shared the new bones' names: kept, renamed {new}"


def _references(obj):
    """(owner, property) pairs that may name one of ``obj``'s vertex groups:
    its modifiers' and particle systems' vertex-group settings, its shape
    keys' vertex groups, and the subtarget of other objects' constraints
    aimed at it."""
    owners = list(obj.modifiers) + [system for system in getattr(obj, "particle_systems", ())]
    for owner in owners:
        for prop in owner.bl_rna.properties:
            if prop.type == "STRING" and "vertex_group" in prop.identifier and not prop.is_readonly:
                yield owner, prop.identifier
    keys = obj.data.shape_keys
    if keys is not None:
        for block in keys.key_blocks:
            yield block, "vertex_group"
    for other in bpy.data.objects:
        for constraint in getattr(other, "constraints", ()):
            if getattr(constraint, "target", None) == obj and hasattr(constraint, "subtarget"):
                yield constraint, "subtarget"


@contextmanager
def renamed_artist_groups(obj, renames: dict):
    """Rename ``obj``'s groups as ``renames`` says (the ones still there) and
    point what used them at the new names while the block runs and after.
    If the block raises, the names and references are put back (a name the
    block has taken meanwhile comes back with the caller's
    :func:`~.snapshot.restored_on_failure`)."""
    renamed, changed = [], []
    try:
        for old, new in renames.items():
            group = obj.vertex_groups.get(old)
            if group is None:
                continue
            group.name = new
            renamed.append((new, old))
            # A modifier takes only the name of an existing group: the group is renamed first.
            for owner, prop in _references(obj):
                if getattr(owner, prop) == old:
                    setattr(owner, prop, new)
                    changed.append((owner, prop, old))
        yield
    except BaseException:
        for new, old in reversed(renamed):
            group = obj.vertex_groups.get(new)
            if group is not None and obj.vertex_groups.get(old) is None:
                group.name = old
        for owner, prop, old in reversed(changed):
            setattr(owner, prop, old)
        raise
