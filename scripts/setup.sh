#!/usr/bin/env bash
# Create .venv (Python 3.11, the Python of Blender 4.2-5.0 and of the bpy
# wheel), install requirements.txt into it and the package itself (editable).
#
# With --older-blenders, create instead one venv per older Blender release
# listed in scripts/older_blenders.sh (.venv-bpy4.2, .venv-bpy4.5), for
# scripts/test_older_blenders.sh: that release's bpy with numpy 1.x, scipy,
# pytest and the package (editable), and no torch, as in the Blender that
# users install the extension into.
# Safe to run again.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

export PIP_NO_INPUT=1 PIP_DISABLE_PIP_VERSION_CHECK=1
PYTHON="${PYTHON:-python3.11}"
REQUIRED_PYTHON="3.11"

case "${1:-}" in
    "") older_blenders=false ;;
    --older-blenders) older_blenders=true ;;
    *) echo "usage: bash scripts/setup.sh [--older-blenders]" >&2; exit 2 ;;
esac

# A Python 3.11 venv at $1, created unless it exists.
make_venv() {
    local venv="$1"
    if [ ! -x "${venv}/bin/python" ]; then
        if ! command -v "${PYTHON}" >/dev/null 2>&1; then
            echo "error: ${PYTHON} not found; install Python ${REQUIRED_PYTHON} or set PYTHON=/path/to/python3.11" >&2
            exit 1
        fi
        "${PYTHON}" -m venv "${venv}"
    fi
    local venv_version
    venv_version="$("${venv}/bin/python" -c 'import sys; print("%d.%d" % sys.version_info[:2])')"
    if [ "${venv_version}" != "${REQUIRED_PYTHON}" ]; then
        echo "error: ${venv} uses Python ${venv_version}, the bpy wheel needs ${REQUIRED_PYTHON}; delete ${venv} and rerun" >&2
        exit 1
    fi
}

# The package itself into the venv $1, editable: `import autorig_addon` works
# from any folder (scripts/, bench/, subprocesses) and edits take effect
# without reinstalling.
install_package() {
    "$1/bin/pip" install -q --no-deps -e .
}

if [ "${older_blenders}" = false ]; then
    make_venv .venv
    .venv/bin/pip install -q -r requirements.txt
    install_package .venv
    exit 0
fi

source scripts/older_blenders.sh
for bpy_version in "${OLDER_BPY_VERSIONS[@]}"; do
    venv="$(older_bpy_venv "${bpy_version}")"
    echo "${venv}: bpy ${bpy_version}"
    make_venv "${venv}"
    # numpy<2: the bpy 4.2 wheel leaves numpy unpinned, but Blender 4.2 ships
    # numpy 1.26, as later wheels pin it (numpy<2.0,>=1.26).
    "${venv}/bin/pip" install -q "bpy==${bpy_version}" "numpy<2" scipy pytest
    install_package "${venv}"
done
