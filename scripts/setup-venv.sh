#!/usr/bin/env bash
# Create .venv with a Python >= 3.12 and install unibuckle_fenicsx with the DOLFINx wheel.
# Usage: scripts/setup-venv.sh [VENV_DIR]   (idempotent; reinstalls when pyproject.toml changes)
set -euo pipefail
cd "$(dirname "$0")/.."
venv=${1:-.venv}
stamp="$venv/.installed"

ok() {  # ok PYTHON -> true if it runs and is >= 3.12
  "$1" -c 'import sys; sys.exit(0 if sys.version_info >= (3, 12) else 1)' >/dev/null 2>&1
}

find_python() {
  local c
  if [ -n "${PYTHON:-}" ] && ok "$PYTHON"; then echo "$PYTHON"; return; fi
  for c in python3.13 python3.12 python3; do
    if command -v "$c" >/dev/null 2>&1 && ok "$c"; then command -v "$c"; return; fi
  done
  if command -v pyenv >/dev/null 2>&1; then
    for c in $(ls -d "$(pyenv root)"/versions/3.1[2-9]*/bin/python3.1[2-9] 2>/dev/null | sort -rV); do
      if ok "$c"; then echo "$c"; return; fi
    done
  fi
  for c in /usr/bin/python3.13 /usr/bin/python3.12 /usr/local/bin/python3.13 /usr/local/bin/python3.12; do
    if [ -x "$c" ] && ok "$c"; then echo "$c"; return; fi
  done
  return 1
}

if [ -f "$stamp" ] && [ "$stamp" -nt pyproject.toml ] && "$venv/bin/python" -c 'import unibuckle_fenicsx' 2>/dev/null; then
  exit 0
fi
if [ ! -x "$venv/bin/python" ]; then
  if ! py=$(find_python); then
    echo "setup: no Python >= 3.12 found (tried \$PYTHON, python3.13, python3.12, python3, pyenv versions)." >&2
    echo "setup: the DOLFINx wheel needs Python >= 3.12: install one (e.g. 'pyenv install 3.12'," >&2
    echo "setup: or 'apt-get install python3.12-venv') or set PYTHON=/path/to/python3.12." >&2
    exit 1
  fi
  echo "setup: creating $venv with $py ($("$py" --version 2>&1))"
  "$py" -m venv "$venv"
fi
"$venv/bin/python" -m pip install --quiet --upgrade pip
"$venv/bin/python" -m pip install --quiet -e '.[fenics,demo,test,lint,sdp,progress,gmsh]'
if ! err=$("$venv/bin/python" -c 'import gmsh' 2>&1); then
  # The gmsh wheel links the system's OpenGL/X11 client libraries (not X itself).
  echo "setup: gmsh is installed but does not load: ${err##*$'\n'}" >&2
  echo "setup: install its system libraries, e.g. 'apt-get install libglu1-mesa libxcursor1" >&2
  echo "setup: libxft2 libxinerama1 libgl1', then rerun; plates meshed by gmsh need it" >&2
  exit 1
fi
touch "$stamp"
echo "setup: $venv ready ($("$venv/bin/python" --version))"
