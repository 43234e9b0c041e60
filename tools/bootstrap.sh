#!/usr/bin/env bash
# Install what layercontact needs, idempotently, as root or as a normal user:
#   - the build's libraries are looked for first where the build looks (pkg-config, the
#     compilers, hypre's headers and library; environment modules set these paths): with
#     all found nothing is installed and no package manager is called;
#   - only what is missing is installed, with apt-get, where apt-get exists and may be used
#     (as root, or through sudo without a password); otherwise the script stops and lists
#     what is missing and how to provide it (packages or modules);
#   - a virtual environment .venv with the package (pip install .) and the test tools.
# Used by `make run` and `make test`; safe to run again (it only does what is missing).
# Environment: FC, CC (compilers), PYTHON (the interpreter of .venv), HYPRE_INCLUDE (the
# directory of HYPRE.h, else from pkg-config HYPRE, $HYPRE_DIR or $HYPRE_ROOT, else
# /usr/include/hypre).
set -euo pipefail
cd "$(dirname "$0")/.."

fc=${FC:-gfortran}
cc=${CC:-cc}

hypre_include=${HYPRE_INCLUDE:-}
if [ -z "$hypre_include" ] && command -v pkg-config >/dev/null 2>&1 && pkg-config --exists HYPRE 2>/dev/null; then
  hypre_include=$(pkg-config --variable=includedir HYPRE)
  [ -f "$hypre_include/HYPRE.h" ] || hypre_include="$hypre_include/hypre"
fi
for root in "${HYPRE_DIR:-}" "${HYPRE_ROOT:-}"; do
  [ -z "$hypre_include" ] && [ -n "$root" ] && [ -f "$root/include/HYPRE.h" ] && hypre_include="$root/include"
done
hypre_include=${hypre_include:-/usr/include/hypre}

has_pc() { command -v pkg-config >/dev/null 2>&1 && pkg-config --exists "$@" 2>/dev/null; }
# a library the C compiler links by name (its default paths, LIBRARY_PATH)
links() {
  local found
  found=$("$cc" -print-file-name="lib$1.so" 2>/dev/null) || return 1
  [ "$found" != "lib$1.so" ] && return 0
  for dir in ${LIBRARY_PATH//:/ } ${LD_LIBRARY_PATH//:/ }; do
    [ -e "$dir/lib$1.so" ] || [ -e "$dir/lib$1.a" ] && return 0
  done
  return 1
}
# the same, or pkg-config HYPRE's
has_library() { links "$1" || has_pc HYPRE; }
# an HDF5 built with MPI-IO: its pkg-config flavours, its parallel compiler wrapper, or
# H5_HAVE_PARALLEL in the H5pubconf.h that pkg-config hdf5 points at
parallel_hdf5() {
  has_pc hdf5-openmpi || has_pc hdf5-mpich || command -v h5pfc || {
    local dir
    for dir in $(pkg-config --cflags-only-I hdf5 2>/dev/null); do
      grep -qs 'define H5_HAVE_PARALLEL 1' "${dir#-I}/H5pubconf.h" && return 0
    done
    return 1
  }
}

# What the build needs: "name|found?|Debian packages|how else to provide it"
missing=()
packages=()
need() {
  local name=$1 test=$2 debian=$3 other=$4
  if ! eval "$test" >/dev/null 2>&1; then
    missing+=("$name: $other")
    packages+=($debian)
  fi
}
need "Fortran compiler ($fc)" 'command -v "$fc"' gfortran "gfortran in PATH, or FC=... (module load gcc)"
need "C compiler ($cc)" 'command -v "$cc"' gcc "cc in PATH, or CC=..."
need "pkg-config" 'command -v pkg-config' pkg-config "pkg-config (or pkgconf) in PATH"
# (the threads of a solve need nothing more: gfortran brings OpenMP, libfftw3-dev FFTW's
# fftw3_omp; a build without fftw3_omp runs on one thread)
need "FFTW 3" 'has_pc fftw3' libfftw3-dev "fftw3.pc in PKG_CONFIG_PATH (module load fftw)"
need "LAPACK" 'has_pc lapack' "liblapack-dev libopenblas-dev" \
  "lapack.pc in PKG_CONFIG_PATH (module load openblas, or a LAPACK with its pkg-config file)"
need "HDF5 with Fortran" 'has_pc hdf5 || command -v h5fc || command -v h5pfc' libhdf5-dev \
  "hdf5.pc in PKG_CONFIG_PATH or h5fc in PATH (module load hdf5, a build with Fortran)"
# result files written by slabs of rows on several MPI ranks: HDF5's MPI-IO
need "parallel HDF5 (MPI-IO)" 'parallel_hdf5' libhdf5-openmpi-dev \
  "hdf5-openmpi.pc in PKG_CONFIG_PATH or h5pfc in PATH (module load hdf5, its MPI build: hdf5-mpi, phdf5)"
need "MPI (C), for hypre" 'has_pc ompi-c || has_pc mpi-c || has_pc mpich || command -v mpicc' libopenmpi-dev \
  "mpicc in PATH or its pkg-config file (module load openmpi, the MPI hypre was built with)"
# one surface on several MPI ranks (docs/decisions/023-mpi-slabs.md): FFTW-MPI and mpirun;
# a build without them runs each solve in one process
need "FFTW-MPI" '[ -f "$(pkg-config --variable=includedir fftw3 2>/dev/null)/fftw3-mpi.f03" ] && links fftw3_mpi' \
  libfftw3-mpi-dev "fftw3-mpi.f03 beside fftw3.f03 and libfftw3_mpi (module load fftw, its MPI build)"
need "mpirun" 'command -v mpirun' openmpi-bin "mpirun in PATH (module load openmpi)"
need "hypre" '[ -f "$hypre_include/HYPRE_parcsr_ls.h" ] && has_library HYPRE' libhypre-dev \
  "HYPRE_parcsr_ls.h in HYPRE_INCLUDE (now $hypre_include) and libHYPRE in LIBRARY_PATH (module load hypre)"

if [ ${#missing[@]} -gt 0 ]; then
  sudo=""
  apt_usable=0
  if command -v apt-get >/dev/null 2>&1; then
    if [ "$(id -u)" -eq 0 ]; then
      apt_usable=1
    elif command -v sudo >/dev/null 2>&1 && sudo -n true >/dev/null 2>&1; then
      apt_usable=1
      sudo="sudo -n"
    fi
  fi
  if [ $apt_usable -eq 0 ]; then
    {
      echo "bootstrap: the build needs what is not found here, and apt-get cannot be used (not root, no sudo):"
      for m in "${missing[@]}"; do echo "  - $m"; done
      echo "Provide them as packages (Debian/Ubuntu, by an administrator: apt-get install ${packages[*]})"
      echo "or as environment modules (module load ...; docs/clusters.md, 'Building on a cluster with modules'),"
      echo "then run this script again."
    } >&2
    exit 1
  fi
  echo "bootstrap: installing system packages: ${packages[*]}"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${packages[@]}" >/dev/null
fi

python=${PYTHON:-python3}
if [ ! -x .venv/bin/python ]; then
  echo "bootstrap: creating .venv"
  "$python" -m venv .venv
  .venv/bin/python -m pip install -q --upgrade pip
fi

# Rebuild the package only when a source file changed since the last install.
stamp=.venv/.layercontact-installed
if [ ! -f "$stamp" ] || [ -n "$(find src app driver meson.build meson.options pyproject.toml -newer "$stamp" -print -quit)" ]; then
  echo "bootstrap: building and installing layercontact into .venv (about a minute once downloaded)"
  setup=()
  [ "$hypre_include" = /usr/include/hypre ] || setup=(-Csetup-args=-Dhypre_include="$hypre_include")
  .venv/bin/python -m pip install -q "${setup[@]}" ".[test]" meson ninja
  touch "$stamp"
fi
