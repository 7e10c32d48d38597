#!/usr/bin/env bash
# Run the test suite in .venv (made by scripts/setup.sh), as CI does, in two
# passes that together run every test once:
#   1. the tests marked `torch` (the training code), with torch;
#   2. the whole suite with torch hidden, as where it is not installed (the
#      extension runs without it): tests/without_torch/sitecustomize.py makes
#      `import torch` fail in pytest and in every process it starts. The torch
#      tests skip themselves (pytest.importorskip), and -rs lists each skip
#      with its reason.
# Arguments go to both pytest runs (a test file, -x, -k ...). The exit status
# is the first failing pass's; pass 1 finding no marked test fails only when
# the whole suite runs (a file chosen by argument may hold none).
set -uo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

PYTHON=.venv/bin/python
WITHOUT_TORCH="${PWD}/tests/without_torch"

printf '\n---------- Tests that need torch (-m torch) ----------\n'
"${PYTHON}" -m pytest -q -m torch "$@"
with_torch=$?
if [ "${with_torch}" -eq 5 ]; then
    echo "(no test marked torch was collected)"
    if [ "$#" -gt 0 ]; then
        with_torch=0
    fi
fi

printf '\n---------- All tests, torch hidden ----------\n'
PYTHONPATH="${WITHOUT_TORCH}${PYTHONPATH:+:${PYTHONPATH}}" "${PYTHON}" -m pytest -q -rs "$@"
without_torch=$?

if [ "${with_torch}" -ne 0 ]; then
    exit "${with_torch}"
fi
exit "${without_torch}"
