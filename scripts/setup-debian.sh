#!/usr/bin/env bash
# Installs the Debian 12 packages nave needs to build, test and run (or the packages given as arguments), only
# those missing: `apt-get update` runs once and only when something must be installed, so a machine that has
# everything is left untouched.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config git
  libembree-dev            # Embree 3: ray tracing inside a brick
  libdraco-dev             # Draco: brick mesh compression
  libmeshoptimizer-dev     # meshoptimizer: simplification of bricks into levels of detail
  libopenvdb-dev libboost-iostreams-dev zlib1g-dev libblosc-dev  # OpenVDB (participating media); its Find module needs these but the package does not pull them in
  libopenimageio-dev openimageio-tools  # OpenImageIO: EXR/PNG output, textures (its CMake config requires the tools)
  liblz4-dev               # LZ4: side sections and temporary bins
  libxxhash-dev            # xxHash: checksums of every stored section
  libjemalloc-dev          # jemalloc: nave's allocator (paging bricks fragments glibc's heap)
  libtbb-dev               # TBB: thread pools
  libgtest-dev libgmock-dev googletest  # GoogleTest
  libbenchmark-dev         # Google Benchmark
  libtomlplusplus-dev      # toml++: scene configs
  libcli11-dev             # CLI11: command-line parsing
  libspdlog-dev libfmt-dev # logging and formatting
  libtinygltf-dev          # glTF 2.0 / GLB import
  libassimp-dev            # the long tail of CAD formats (FBX, DAE, 3DS, DXF...)
  libocct-data-exchange-dev libocct-modeling-algorithms-dev  # Open CASCADE: STEP and IGES, tessellated
  libifcplusplus-dev       # IFC++ with Carve: IFC 2x3 and IFC 4 building models
  libopenmpi-dev openmpi-bin  # Open MPI: the distributed render under mpirun (docs/distributed.md)
)

# Other scripts pass their own list (bench/setup-bench.sh): install those instead.
if (($# > 0)); then packages=("$@"); fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]} == 0)); then
  exit 0
fi
echo "nave setup: installing ${#missing[@]} missing Debian packages: ${missing[*]}" >&2
as_root=()
if [[ $(id -u) -ne 0 ]]; then as_root=(sudo); fi
export DEBIAN_FRONTEND=noninteractive
# Waits for another install on the same machine rather than failing on its dpkg lock.
lock_wait=(-o DPkg::Lock::Timeout=600)
"${as_root[@]}" apt-get "${lock_wait[@]}" update -qq
"${as_root[@]}" apt-get "${lock_wait[@]}" install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "nave setup: done" >&2
