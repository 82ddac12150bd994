#!/usr/bin/env bash
# Create (or reuse) the virtual environment at .venv in the repository root and
# install the pinned dependencies from requirements.txt into it, and the farm
# command's (requirements-farm.txt: Dask distributed) so its tests run.  When a Python
# 3.13 is available (python3.13 on the PATH, or pyenv's), also create
# .venv-bpy52 from requirements-bpy52.txt: Blender 5.2 LTS as a module, for
# the Blender tests (.ci/run).  Re-running is cheap: pip is only invoked when
# a requirements file changed since the last run (a stamp file in each venv).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
python="${PYTHON:-python3}"
if [ ! -x .venv/bin/python ]; then
    "$python" -m venv .venv
fi
stamp=.venv/.requirements.sha256
want="$(cat requirements.txt requirements-farm.txt | sha256sum | cut -d' ' -f1)"
if [ ! -f "$stamp" ] || [ "$(cat "$stamp")" != "$want" ]; then
    .venv/bin/python -m pip install --quiet --upgrade pip
    .venv/bin/python -m pip install --quiet -r requirements.txt -r requirements-farm.txt
    echo "$want" > "$stamp"
fi

# A Python 3.13 that runs (pyenv's shim exists even when 3.13 is not selected).
python313=""
for candidate in "${PYTHON313:-}" "$(command -v python3.13 || true)" \
    "$(command -v pyenv >/dev/null && pyenv root)"/versions/3.13*/bin/python3.13; do
    if [ -n "$candidate" ] && [ -x "$candidate" ] && "$candidate" -c "" 2>/dev/null; then
        python313="$candidate"
        break
    fi
done
if [ -n "$python313" ]; then
    if [ ! -x .venv-bpy52/bin/python ]; then
        "$python313" -m venv .venv-bpy52
    fi
    stamp=.venv-bpy52/.requirements.sha256
    want="$(sha256sum requirements-bpy52.txt | cut -d' ' -f1)"
    if [ ! -f "$stamp" ] || [ "$(cat "$stamp")" != "$want" ]; then
        .venv-bpy52/bin/python -m pip install --quiet --upgrade pip
        .venv-bpy52/bin/python -m pip install --quiet -r requirements-bpy52.txt
        echo "$want" > "$stamp"
    fi
fi

# The Mitsuba 3 environment (.venv-mitsuba, requirements-mitsuba.txt) for the
# polarized plugin germer_paint.  Where its packages cannot be installed (no
# wheels for this platform, no network), say so and go on: its tests are
# then skipped, and scripts/test.sh says that too.
if [ ! -x .venv-mitsuba/bin/python ]; then
    "$python" -m venv .venv-mitsuba
fi
stamp=.venv-mitsuba/.requirements.sha256
want="$(sha256sum requirements-mitsuba.txt | cut -d' ' -f1)"
if [ ! -f "$stamp" ] || [ "$(cat "$stamp")" != "$want" ]; then
    rm -f "$stamp"  # until it installs: test.sh runs the Mitsuba tests only where it did
    if .venv-mitsuba/bin/python -m pip install --quiet --upgrade pip \
        && .venv-mitsuba/bin/python -m pip install --quiet -r requirements-mitsuba.txt; then
        echo "$want" > "$stamp"
    else
        echo "bootstrap.sh: Mitsuba 3 could not be installed into .venv-mitsuba; its tests will be skipped" >&2
    fi
fi
