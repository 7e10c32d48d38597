"""Scene file formats the add-on reads and writes (through Blender's own
importers and exporters), declared without Blender so the command line can
name them in ``--help`` and pick files from folders before Blender loads."""

#: File extensions ``blender.scene_io.load_scene`` reads.
LOADABLE_EXTENSIONS = (".blend", ".glb", ".gltf", ".fbx", ".obj")
#: File extensions ``blender.scene_io.save_scene`` writes (Blender has no OBJ armatures).
SAVABLE_EXTENSIONS = (".blend", ".glb", ".gltf", ".fbx")
