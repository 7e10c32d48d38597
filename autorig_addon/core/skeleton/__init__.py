"""Skeleton logic on plain arrays.

* :mod:`.hierarchy`: children, roots, parents-first order, descendant
  counts and subsets of a parent array.
* :mod:`.checks`: whether Blender can hold a skeleton (zero-length bones,
  name lengths).
* :mod:`.tails`: bone tails derived from the joints.
* :mod:`.posing`: random poses, pose matrices and linear blend skinning
  (Blender's Armature modifier).
* :mod:`.naming`: Blender's bone naming conventions (``.L`` / ``.R``
  sides, numbered chains).
"""
