#!/usr/bin/env bash
# Installs everything rfem needs on Debian 12 (run as root): Debian packages, then SUNDIALS 6.4.1
# (IDA and ARKODE, Release, no MPI) built from Debian's source package into .deps/sundials.
# Why not libsundials-dev: it is built at -O0 and pulls in MPI/PETSc (IDA ran 2.7× slower with it).
# Idempotent: packages already present and an existing SUNDIALS build are reused.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
prefix="$here/.deps/sundials"

pkgs=(build-essential cmake ninja-build pkg-config dpkg-dev ca-certificates
      libeigen3-dev libsuitesparse-dev libhdf5-dev hdf5-tools libtomlplusplus-dev libcli11-dev
      libfmt-dev libspdlog-dev nlohmann-json3-dev libgtest-dev libgmock-dev libbenchmark-dev libspectra-dev
      python3 python3-dev python3-numpy python3-scipy python3-h5py python3-matplotlib python3-pytest pybind11-dev
      python3-venv python3-pip python3-setuptools python3-wheel python3-mypy
      python3-nbclient python3-nbformat python3-ipykernel
      liburdfdom-dev libopenmpi-dev openmpi-bin clang libclang-rt-14-dev libomp-14-dev)
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "install-deps: apt-get install ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# ARKODE supplies the Butcher tables of the ESDIRK methods (solvers/esdirk.cpp); a prefix from
# an older checkout without it is rebuilt.
if ls "$prefix"/lib*/libsundials_arkode.a >/dev/null 2>&1; then
  echo "install-deps: SUNDIALS already built in $prefix"
  exit 0
fi

# deb-src for sundials through a private apt configuration (the system's lists stay untouched).
rm -rf "$prefix"
work="$here/.deps/src"; rm -rf "$work"; mkdir -p "$work/lists/partial" "$work/archives/partial"
srclist="$work/sources.list"
: >"$srclist"
for f in /etc/apt/sources.list /etc/apt/sources.list.d/*.list; do
  [[ -f $f ]] && awk '$1=="deb" && /debian/ {$1="deb-src"; print}' "$f" >>"$srclist"
done
for f in /etc/apt/sources.list.d/*.sources; do
  [[ -f $f ]] || continue
  grep -q 'debian' "$f" || continue
  awk 'BEGIN{RS="";FS="\n"} /URIs:[^\n]*debian/ {
         for (i=1;i<=NF;i++){ if ($i ~ /^Types:/) $i="Types: deb-src"; print $i } print "" }' "$f" \
    >"$work/$(basename "$f")"
done
aptopts=(-o "Dir::Etc::SourceList=$srclist" -o "Dir::Etc::SourceParts=$work"
         -o "Dir::State::Lists=$work/lists" -o "Dir::Cache::Archives=$work/archives"
         -o "APT::Sandbox::User=root")
apt-get "${aptopts[@]}" update -qq
(cd "$work" && apt-get "${aptopts[@]}" source --download-only sundials >/dev/null)
tarball=$(ls "$work"/sundials_*.orig.tar.* | head -n1)
mkdir -p "$work/sundials" && tar -xf "$tarball" -C "$work/sundials" --strip-components=1
cmake -S "$work/sundials" -B "$work/build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_INSTALL_PREFIX="$prefix" -DBUILD_ARKODE=ON -DBUILD_CVODE=OFF -DBUILD_CVODES=OFF \
  -DBUILD_IDA=ON -DBUILD_IDAS=OFF -DBUILD_KINSOL=OFF -DBUILD_FORTRAN_MODULE_INTERFACE=OFF \
  -DENABLE_MPI=OFF -DENABLE_OPENMP=OFF -DENABLE_PTHREAD=OFF -DEXAMPLES_ENABLE_C=OFF \
  -DEXAMPLES_INSTALL=OFF -DBUILD_SHARED_LIBS=OFF -DBUILD_STATIC_LIBS=ON \
  -DSUNDIALS_INDEX_SIZE=64 -DCMAKE_POSITION_INDEPENDENT_CODE=ON >/dev/null
cmake --build "$work/build" -j "$(nproc)" >/dev/null
cmake --install "$work/build" >/dev/null 2>&1
rm -rf "$work"
echo "install-deps: SUNDIALS $(ls "$prefix"/lib*/libsundials_ida* | head -n1) built"
