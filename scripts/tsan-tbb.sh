#!/usr/bin/env bash
# Builds Debian's own oneTBB (the source package of the installed libtbb-dev, with Debian's patches) with
# -fsanitize=thread into build/deps/tbb-tsan, for the `tsan` preset. ThreadSanitizer sees a TBB task's
# hand-off from the thread that spawns it to the one that runs it only if libtbb itself is instrumented;
# with Debian's binary libtbb every parallel_for is reported as a race. Skips everything when the build
# for this version is already there. `scripts/test.sh tsan` calls it. Exit code 3: what it needs could
# not be downloaded (no network); anything else non-zero is a failure of the build itself.
set -euo pipefail
cd "$(dirname "$0")/.."

# The source this script knows, checked against the archive's Sources index (SHA-256 of each file).
version=2021.8.0
debian_revision=2+deb12u1
orig_sha256=7e9111b8bb59c8800bf6d0b06afe7b0891937443d2dae1ee1101c8e2ede6a7ef
debian_sha256=b83a270205b38cdf66972fa1467c3e29493b88b92ecacf4f3672e87d67199df5

prefix=build/deps/tbb-tsan
stamp="$prefix/.built-$version-$debian_revision"
if [[ -f $stamp ]]; then exit 0; fi

if ! bash scripts/setup-debian.sh build-essential cmake ninja-build curl ca-certificates xz-utils patch libtbb-dev; then
  echo "nave tsan-tbb: cannot install the packages needed to fetch and build oneTBB" >&2
  exit 3
fi
installed=$(dpkg-query -W -f='${Version}' libtbb-dev)
if [[ $installed != "$version-$debian_revision" ]]; then
  echo "nave tsan-tbb: libtbb-dev $installed is installed but this script builds $version-$debian_revision;" \
    "update version, debian_revision and the two SHA-256 sums in scripts/tsan-tbb.sh from" \
    "http://deb.debian.org/debian/dists/bookworm/main/source/Sources.xz (package onetbb)" >&2
  exit 1
fi

work=build/deps/tbb-tsan-src
rm -rf "$work" "$prefix"
mkdir -p "$work"
fetch() {  # FILE SHA256: from the Debian pool, or from the snapshot archive once the pool has moved on
  local file=$1 sum=$2 url
  for url in "http://deb.debian.org/debian/pool/main/o/onetbb/$file" \
             "http://snapshot.debian.org/archive/debian/20250520T000000Z/pool/main/o/onetbb/$file"; do
    if curl -fsSL --retry 3 -o "$work/$file" "$url" && echo "$sum  $work/$file" | sha256sum -c --quiet -; then
      return 0
    fi
  done
  echo "nave tsan-tbb: cannot download $file with SHA-256 $sum from the Debian archive" >&2
  return 1
}
orig=onetbb_$version.orig.tar.xz
deb=onetbb_$version-$debian_revision.debian.tar.xz
fetch "$orig" "$orig_sha256" || exit 3
fetch "$deb" "$debian_sha256" || exit 3
tar -C "$work" -xf "$work/$orig"
tar -C "$work/oneTBB-$version" -xf "$work/$deb"
(cd "$work/oneTBB-$version" && while read -r p; do
  [[ -z $p || $p == \#* ]] || patch -p1 -s < "debian/patches/$p"
done < debian/patches/series)

echo "nave tsan-tbb: building oneTBB $version with ThreadSanitizer (about a minute)" >&2
cmake -S "$work/oneTBB-$version" -B "$work/build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DTBB_SANITIZE=thread -DTBB_TEST=OFF -DTBB_STRICT=OFF -DTBBMALLOC_BUILD=OFF \
  -DCMAKE_INSTALL_PREFIX="$PWD/$prefix" >/dev/null
cmake --build "$work/build" -j "$(nproc)" >/dev/null
cmake --install "$work/build" >/dev/null
rm -rf "$work"
touch "$stamp"
