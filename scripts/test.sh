#!/usr/bin/env bash
# The README's test command runs this after scripts/bootstrap.sh: the test
# suite in each environment bootstrap.sh made — every test under .venv (Blender 5.0's
# pip bpy); the Blender test files again under .venv-bpy52 (Blender 5.2 LTS)
# when a Python 3.13 made it; the Mitsuba 3 plugin's under .venv-mitsuba when
# Mitsuba installed there.  Options go to every pytest run (for example
# -m "not render" or -k NAME); give test files to the venvs' pytest directly.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"

# Every environment runs, whatever the one before it gave; the exit status is
# the first failure's.  pytest's 5 (no test selected, e.g. -k matching only
# another environment's tests) counts as a pass.
status=0
run() {
    local code=0
    "$@" || code=$?
    if [ "$code" -ne 0 ] && [ "$code" -ne 5 ] && [ "$status" -eq 0 ]; then
        status=$code
    fi
}

# Cycles renders (the ``cycles`` marker) run once: under Blender 5.2 LTS when
# .venv-bpy52 exists, else under 5.0.  EEVEE renders run under both, each
# against its own version's tables.
if [ -x .venv-bpy52/bin/python ]; then
    run env PAINT_LUT_CYCLES_ELSEWHERE="Blender 5.2 LTS (.venv-bpy52)" .venv/bin/python -m pytest "$@"
else
    run .venv/bin/python -m pytest "$@"
fi

if [ -x .venv-bpy52/bin/python ]; then
    mapfile -t blender_tests < <(grep -l 'importorskip("bpy")' tests/test_*.py)
    run .venv-bpy52/bin/python -m pytest "${blender_tests[@]}" "$@"
else
    echo "test.sh: no Python 3.13 here, so the Blender tests ran under Blender 5.0 only" >&2
fi

if [ -f .venv-mitsuba/.requirements.sha256 ]; then
    mapfile -t mitsuba_tests < <(grep -l 'importorskip("mitsuba")' tests/test_*.py)
    run .venv-mitsuba/bin/python -m pytest "${mitsuba_tests[@]}" "$@"
else
    echo "test.sh: Mitsuba 3 is not installed (.venv-mitsuba), so the polarized plugin's tests were skipped" >&2
fi
exit "$status"
