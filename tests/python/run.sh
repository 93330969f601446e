#!/usr/bin/env bash
# The Python package on a real CPython: builds the wheel with maturin (from PyPI) into a venv, on the
# same release profile and target directory as the Rust tests (only the bindings crate and the link
# are new), installs it, runs the pytest tests (python/tests), the example script
# (examples/sweep_inner_swing.py) and, once, the overhead benchmark (python/benchmarks/overhead.py,
# printed, not asserted: speed targets are benchmarks, not tests).
#
#   tests/python/run.sh
#
# The venv is kept at $RINSCOPE_PY_VENV (default ~/.cache/rinscope-py-venv) so that rerun-sdk, pandas
# and maturin are downloaded once; RINSCOPE_SKIP_PYTHON=1 skips all this and says so. Last line:
# "python: N passed, M failed". About 1-2 min warm.
set -euo pipefail
if [[ ${RINSCOPE_SKIP_PYTHON:-} == 1 ]]; then
  echo "python: SKIPPED (RINSCOPE_SKIP_PYTHON=1): the Python package was not built or tested"
  exit 0
fi
root=$(cd "$(dirname "$0")/../.." && pwd)
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$HOME/.cache/rinscope-target}"
venv=${RINSCOPE_PY_VENV:-$HOME/.cache/rinscope-py-venv}
py=${PYTHON:-python3}
[ -x "$venv/bin/python" ] || { "$py" -m venv "$venv" && "$venv/bin/pip" install -q --upgrade pip; }
# ipykernel: a test interrupts a run in a real Jupyter kernel (jupyter_client comes with rerun-notebook).
if ! "$venv/bin/python" -c "import maturin, pytest, pandas, matplotlib, rerun, rerun_notebook, ipykernel, jupyter_client" 2>/dev/null; then
  "$venv/bin/pip" install -q "maturin>=1.9,<2" pytest matplotlib pandas numpy "rerun-sdk[notebook]==0.36.3" ipykernel jupyter_client
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
started=$(date +%s)
# The wheel, as a user without Rust would get it: maturin build, then pip install of the file.
(cd "$root/python" && "$venv/bin/maturin" build --release --quiet -o "$work/wheels" 2>&1 | tail -2)
wheel=$(ls "$work"/wheels/rinscope-*.whl)
echo "python: built $(basename "$wheel") ($(du -k "$wheel" | cut -f1) kB) in $(( $(date +%s) - started )) s"
"$venv/bin/pip" install -q --force-reinstall --no-deps "$wheel"
"$venv/bin/pip" install -q "$wheel"   # its declared dependencies, if any is missing
# The tests run from a folder outside the repository, on the installed package.
mkdir -p "$work/run"
cd "$work/run"
set +e
"$venv/bin/python" -m pytest -q -p no:cacheprovider "$root/python/tests" 2>&1 | tee "$work/pytest.txt" | tail -25
tests=${PIPESTATUS[0]}
"$venv/bin/python" "$root/examples/sweep_inner_swing.py" > "$work/example.txt" 2>&1
example=$?
set -e
tail -4 "$work/example.txt"
[[ $example == 0 && -s sweep_inner_swing.png ]] && "$venv/bin/python" -c "import rinscope; rinscope.verify_recording('recordings/sweep_inner_swing.rrd')" || example=1
"$venv/bin/python" "$root/python/benchmarks/overhead.py" --rounds 20 || true
# The abi3 wheel on the oldest CPython it is built for, when this machine has one (rerun-sdk 0.36.3 needs
# 3.10, so there the package installs without the viewer; the tests that need it skip).
old39=0
py39=
for c in python3.9 "${PYENV_ROOT:-$HOME/.pyenv}"/versions/3.9*/bin/python3.9; do
  "$c" -c "import venv" >/dev/null 2>&1 && { py39=$c; break; }
done
if [[ -n $py39 ]]; then
  venv39=${RINSCOPE_PY39_VENV:-$HOME/.cache/rinscope-py39-venv}
  [ -x "$venv39/bin/python" ] || "$py39" -m venv "$venv39"
  "$venv39/bin/pip" install -q pytest "$wheel" && "$venv39/bin/pip" install -q --force-reinstall --no-deps "$wheel"
  set +e
  PATH="$venv39/bin:$PATH" "$venv39/bin/python" -m pytest -q -p no:cacheprovider "$root/python/tests" > "$work/pytest39.txt" 2>&1
  old39=$?
  set -e
  echo "python 3.9: $(tail -1 "$work/pytest39.txt")"
  [[ $old39 != 0 ]] && tail -30 "$work/pytest39.txt"
else
  echo "python 3.9: not on this machine; the wheel was tested on $("$venv/bin/python" -c 'import sys; print(sys.version.split()[0])') only"
fi
passed=$(grep -oE '[0-9]+ passed' "$work/pytest.txt" | awk '{s += $1} END {print s + 0}' || true)
failed=$(grep -oE '[0-9]+ (failed|errors?)' "$work/pytest.txt" | awk '{s += $1} END {print s + 0}' || true)
if [[ $tests != 0 || $example != 0 || $old39 != 0 ]]; then
  [[ $old39 != 0 ]] && echo "python: the tests failed on CPython 3.9"
  [[ $example != 0 ]] && { echo "python: examples/sweep_inner_swing.py failed:"; tail -20 "$work/example.txt"; }
  echo "python: $passed passed, $(( ${failed:-0} + (example != 0) + (old39 != 0) )) failed"
  exit 1
fi
echo "python: $((passed + 1)) passed, 0 failed (pytest and the example script$([[ -n ${venv39:-} ]] && echo "; pytest on 3.9 too"))"
