# Sourced by scripts/setup.sh and scripts/test_older_blenders.sh: the older
# Blender releases CI tests besides requirements.txt's bpy, the newest bpy
# wheel of each LTS line that blender_manifest.toml's blender_version_min
# (4.2.0) admits. Not 4.2.0 itself: it crashes at exit after a glTF import.
OLDER_BPY_VERSIONS=(4.2.23 4.5.15)

# The venv of one of them: 4.2.23 -> .venv-bpy4.2 (git-ignored).
older_bpy_venv() {
    echo ".venv-bpy${1%.*}"
}
