#!/usr/bin/env bash
# Create .venv (Python 3.11, the Python of Blender 4.2-5.0 and of the bpy
# wheel), install requirements.txt into it and the package itself (editable).
# Safe to run again.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

export PIP_NO_INPUT=1 PIP_DISABLE_PIP_VERSION_CHECK=1
PYTHON="${PYTHON:-python3.11}"
REQUIRED_PYTHON="3.11"

if [ ! -x .venv/bin/python ]; then
    if ! command -v "${PYTHON}" >/dev/null 2>&1; then
        echo "error: ${PYTHON} not found; install Python ${REQUIRED_PYTHON} or set PYTHON=/path/to/python3.11" >&2
        exit 1
    fi
    "${PYTHON}" -m venv .venv
fi
venv_version="$(.venv/bin/python -c 'import sys; print("%d.%d" % sys.version_info[:2])')"
if [ "${venv_version}" != "${REQUIRED_PYTHON}" ]; then
    echo "error: .venv uses Python ${venv_version}, the bpy wheel needs ${REQUIRED_PYTHON}; delete .venv and rerun" >&2
    exit 1
fi
.venv/bin/pip install -q -r requirements.txt
# The package itself, editable: `import autorig_addon` works from any folder
# (scripts/, bench/, subprocesses) and edits take effect without reinstalling.
.venv/bin/pip install -q --no-deps -e .
