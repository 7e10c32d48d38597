#!/usr/bin/env bash
# Run the tests marked `all_blenders` (the install-and-rig smoke test and the
# operator tests) on each older Blender release of scripts/older_blenders.sh,
# in its venv (made by `bash scripts/setup.sh --older-blenders`). These venvs
# have no torch, so nothing needs hiding. scripts/test.sh runs the same tests
# on requirements.txt's bpy with the rest of the suite.
# Arguments go to every pytest run (-x, -k ...). The exit status is the
# first failing release's; every release runs either way.
set -uo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
source scripts/older_blenders.sh

status=0
for bpy_version in "${OLDER_BPY_VERSIONS[@]}"; do
    venv="$(older_bpy_venv "${bpy_version}")"
    printf '\n---------- bpy %s (%s, -m all_blenders) ----------\n' "${bpy_version}" "${venv}"
    installed="$("${venv}/bin/python" -c 'import importlib.metadata as m; print(m.version("bpy"))' 2>/dev/null)"
    if [ "${installed}" != "${bpy_version}" ]; then
        echo "error: ${venv} has bpy '${installed}', not ${bpy_version}; run: bash scripts/setup.sh --older-blenders" >&2
        [ "${status}" -ne 0 ] || status=1
        continue
    fi
    "${venv}/bin/python" -m pytest -q -rs -m all_blenders "$@"
    result=$?
    [ "${status}" -ne 0 ] || status="${result}"
done
exit "${status}"
