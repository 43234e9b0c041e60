#!/usr/bin/env bash
# Install what layercontact needs on a fresh Debian machine, idempotently:
#   - system packages (compiler, FFTW, LAPACK, HDF5) with apt-get, only if missing;
#   - a virtual environment .venv with the package (pip install .) and the test tools.
# Used by `make run` and `make test`; safe to run again (it only does what is missing).
set -euo pipefail
cd "$(dirname "$0")/.."

# libhypre-dev: the leakage's algebraic multigrid (it brings Open MPI); the threads of a solve
# need nothing more: gfortran brings OpenMP (libgomp), libfftw3-dev FFTW's fftw3_omp
packages=(gfortran libfftw3-dev liblapack-dev libopenblas-dev libhdf5-dev libhypre-dev pkg-config)
missing=()
for p in "${packages[@]}"; do
  dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "bootstrap: installing system packages: ${missing[*]}"
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

python=${PYTHON:-python3}
if [ ! -x .venv/bin/python ]; then
  echo "bootstrap: creating .venv"
  "$python" -m venv .venv
  .venv/bin/pip install -q --upgrade pip
fi

# Rebuild the package only when a source file changed since the last install.
stamp=.venv/.layercontact-installed
if [ ! -f "$stamp" ] || [ -n "$(find src app driver meson.build meson.options pyproject.toml -newer "$stamp" -print -quit)" ]; then
  echo "bootstrap: building and installing layercontact into .venv (about a minute once downloaded)"
  .venv/bin/pip install -q ".[test]" meson ninja
  touch "$stamp"
fi
