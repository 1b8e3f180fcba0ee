#!/usr/bin/env bash
# Install SeismicMesh 3.6.2 into its own virtual environment for benchmarks/compare_seismicmesh.py.
#
# SeismicMesh is GPL-3.0 and needs CGAL and MPI, so it is a benchmark-only peer: it lives in
# benchmarks/peers/.venv-seismicmesh and is never a dependency of terramesh.
#
# Usage:  bash benchmarks/peers/setup_seismicmesh.sh            (idempotent; re-running is cheap)
#         PYTHON=python3.11 bash benchmarks/peers/setup_seismicmesh.sh
#         FORCE=1 bash benchmarks/peers/setup_seismicmesh.sh    (rebuild SeismicMesh even if present)
#
# What it does:
#   1. apt-get install libcgal-dev (header-only CGAL 5.x; pulls in GMP, MPFR and Boost headers),
#      only when it is not installed yet. Needs root or sudo (Debian/Ubuntu).
#   2. python -m venv benchmarks/peers/.venv-seismicmesh, only when it does not exist yet.
#   3. pip install the build requirements, then MPI from wheels (mpi4py plus the `mpich` wheel,
#      which ships libmpi inside the venv, so no system MPI is needed), then
#      SeismicMesh==3.6.2 built from source against the venv's numpy<2 and pybind11<3.
#   4. Imports SeismicMesh and meshes a small disk as a smoke test.
set -euo pipefail

SEISMICMESH_VERSION="3.6.2"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
venv="${here}/.venv-seismicmesh"
python="${PYTHON:-python3}"

say() { printf '[setup_seismicmesh] %s\n' "$*"; }
run() {
    say "+ $*"
    "$@"
}

# 1. CGAL headers -----------------------------------------------------------------------------
if dpkg-query -W -f='${Status}' libcgal-dev 2>/dev/null | grep -q "install ok installed"; then
    say "libcgal-dev already installed ($(dpkg-query -W -f='${Version}' libcgal-dev)), skipping apt-get"
else
    if [ "$(id -u)" -eq 0 ]; then
        sudo=()
    elif command -v sudo >/dev/null 2>&1; then
        sudo=(sudo)
    else
        say "error: libcgal-dev is missing and this is not root (and there is no sudo)" >&2
        exit 1
    fi
    run "${sudo[@]}" apt-get update
    run "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends libcgal-dev
fi
if ! command -v c++ >/dev/null 2>&1; then
    say "error: no C++ compiler (c++) found; install g++ first" >&2
    exit 1
fi

# 2. Virtual environment ----------------------------------------------------------------------
if [ -x "${venv}/bin/python" ]; then
    say "virtual environment exists: ${venv}"
else
    run "${python}" -m venv "${venv}"
fi
vpy="${venv}/bin/python"

installed_version() {
    "${vpy}" -c 'import importlib.metadata as m; print(m.version("SeismicMesh"))' 2>/dev/null || true
}

# 3. Packages ---------------------------------------------------------------------------------
if [ "$(installed_version)" = "${SEISMICMESH_VERSION}" ] && [ "${FORCE:-0}" != "1" ]; then
    say "SeismicMesh ${SEISMICMESH_VERSION} already installed in the venv, skipping pip (FORCE=1 to rebuild)"
else
    run "${vpy}" -m pip install --upgrade pip
    # Build requirements, installed first because the build runs without isolation so that it sees them.
    run "${vpy}" -m pip install "setuptools" "wheel" "pybind11>=2.6,<3" "numpy<2"
    # SeismicMesh imports mpi4py at import time; the mpich wheel provides the MPI library.
    run "${vpy}" -m pip install "numpy<2" "mpi4py" "mpich"
    # Compiles six C++ extensions against CGAL (several minutes on a 2-core machine).
    run "${vpy}" -m pip install --no-build-isolation "numpy<2" "SeismicMesh==${SEISMICMESH_VERSION}"
fi

# 4. Smoke test -------------------------------------------------------------------------------
say "smoke test: meshing a unit disk with SeismicMesh"
run "${vpy}" - <<'PY'
import SeismicMesh

points, cells = SeismicMesh.generate_mesh(domain=SeismicMesh.Disk([0.0, 0.0], 1.0), edge_length=0.2, verbose=0)
print(f"SeismicMesh {SeismicMesh.__version__}: {len(points)} vertices, {len(cells)} cells")
PY
say "done: ${vpy}"
