"""Algorithms on plain arrays. Nothing under ``core`` may import ``bpy``."""
