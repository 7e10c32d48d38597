"""Skeleton prediction from a bare mesh (RigNet-style): joints, connectivity, names."""
