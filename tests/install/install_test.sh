#!/usr/bin/env bash
# The installed dynid, as a user gets it (issue 29, README "Install"). One mode per ctest entry
# (tests/install/CMakeLists.txt); each works in a temporary folder it removes.
#   prefix SOURCE BUILD LIBDIR VERSION CXX
#       cmake --install BUILD into a prefix, then moves the prefix: the CLI still finds its robots
#       (a robot file added only to the moved prefix is listed and loads, also when dynid is found
#       on PATH), and examples/consumer builds against the moved prefix with find_package(dynid)
#       and with pkg-config and runs (its libdynid.so finds the robots beside it).
#   subdirectory SOURCE
#       configures examples/consumer with add_subdirectory(SOURCE) (configure only).
#   deb SOURCE BUILD
#       cpack -G DEB: the package holds the CLI, the library, headers, CMake and pkg-config files
#       and the robots, depends on the shared libraries the CLI loads, and its CLI runs unpacked.
#   pip SOURCE BUILD PYTHON
#       pip install --no-build-isolation (offline, reusing BUILD) into a folder; `import dynid`
#       from elsewhere loads the installed package and its robots.
set -euo pipefail
mode=$1
source_dir=$2
unset DYNID_ROBOTS_DIR
tmp=$(mktemp -d "${TMPDIR:-/tmp}/dynid-install-$mode.XXXXXX")
trap 'rm -rf "$tmp"' EXIT

fail() {
  echo "FAIL ($mode): $*" >&2
  exit 1
}
require_file() {
  [ -e "$1" ] || fail "missing $1"
}
# A robot that exists only where the installed files are: finding it proves that lookup, not the
# source tree (which every build also knows).
add_probe_robot() {
  cp "$source_dir/examples/robots/planar2.yaml" "$1/relocated_probe.yaml"
}

case $mode in
prefix)
  build_dir=$3 libdir=$4 version=$5 cxx=$6
  cmake --install "$build_dir" --prefix "$tmp/first" >/dev/null
  mv "$tmp/first" "$tmp/moved"
  p=$tmp/moved
  for f in bin/dynid "$libdir/libdynid.so" include/dynid/version.hpp \
           include/dynid/model/robots.hpp include/dynid/estimation/closed_loop.hpp \
           share/dynid/robots/puma560.yaml \
           "$libdir/cmake/dynid/dynidConfig.cmake" "$libdir/cmake/dynid/dynidConfigVersion.cmake" \
           "$libdir/pkgconfig/dynid.pc"; do
    require_file "$p/$f"
  done
  add_probe_robot "$p/share/dynid/robots"
  cd "$tmp"
  "$p/bin/dynid" --version | grep -Eq "^dynid $version \(commit ([0-9a-f]{12}|unknown)\)$" ||
    fail "dynid --version printed '$("$p/bin/dynid" --version)'"
  listed=$("$p/bin/dynid" model --help | grep "Built-in")
  [[ $listed == *relocated_probe* ]] ||
    fail "the moved dynid does not list its prefix's robots: $listed"
  PATH="$p/bin:$PATH" dynid model --robot relocated_probe >/dev/null ||
    fail "dynid found on PATH does not load a robot of its prefix"

  cmake -S "$source_dir/examples/consumer" -B "$tmp/consumer-cmake" -DCMAKE_PREFIX_PATH="$p" \
    -DCMAKE_CXX_COMPILER="$cxx" -DCMAKE_BUILD_TYPE=Release >"$tmp/log" 2>&1 ||
    fail "find_package(dynid) against the installed prefix: $(cat "$tmp/log")"
  cmake --build "$tmp/consumer-cmake" >"$tmp/log" 2>&1 || fail "consumer build: $(cat "$tmp/log")"
  "$tmp/consumer-cmake/consumer" relocated_probe | grep -q "robot relocated_probe (2 joints)" ||
    fail "the CMake consumer"

  export PKG_CONFIG_PATH=$p/$libdir/pkgconfig
  # shellcheck disable=SC2046  # pkg-config's flags are words
  "$cxx" -std=c++17 -O1 "$source_dir/examples/consumer/main.cpp" -o "$tmp/consumer-pc" \
    $(pkg-config --cflags --libs dynid) -Wl,-rpath,"$(pkg-config --variable=libdir dynid)" ||
    fail "the pkg-config consumer does not build"
  "$tmp/consumer-pc" relocated_probe | grep -q "robot relocated_probe (2 joints)" ||
    fail "the pkg-config consumer"
  ;;
subdirectory)
  cmake -S "$source_dir/examples/consumer" -B "$tmp/parent" -DDYNID_SOURCE="$source_dir" \
    >"$tmp/log" 2>&1 || fail "add_subdirectory(dynid) from a parent project: $(cat "$tmp/log")"
  # A parent project gets the library and the CLI, not dynid's tests, benchmarks, Python module
  # or installed shared library.
  cmake --build "$tmp/parent" --target help >"$tmp/targets"
  grep -q "dynid_lib" "$tmp/targets" || fail "no dynid_lib target in the parent project"
  ! grep -Eq "model_tests|dynid_python|dynid_shared" "$tmp/targets" ||
    fail "the parent project builds dynid's tests, Python module or shared library"
  ;;
deb)
  build_dir=$3
  cd "$tmp"
  cpack -G DEB --config "$build_dir/CPackConfig.cmake" -B "$tmp/deb" >"$tmp/log" 2>&1 ||
    fail "cpack: $(cat "$tmp/log")"
  deb=$(ls "$tmp"/deb/*.deb)
  dpkg-deb -c "$deb" | awk '{print $NF}' >"$tmp/contents"
  for f in ./usr/bin/dynid ./usr/include/dynid/version.hpp ./usr/include/dynid/model/robots.hpp \
           ./usr/share/dynid/robots/puma560.yaml; do
    grep -qx "$f" "$tmp/contents" || fail "$deb lacks $f"
  done
  for pattern in '/libdynid\.so\.[0-9.]+$' '/cmake/dynid/dynidConfig\.cmake$' \
                 '/pkgconfig/dynid\.pc$'; do
    grep -Eq "$pattern" "$tmp/contents" || fail "$deb lacks a file matching $pattern"
  done
  depends=$(dpkg-deb -f "$deb" Depends)
  for dep in libyaml-cpp libmujoco libeigen3-dev nlohmann-json3-dev; do
    [[ $depends == *"$dep"* ]] || fail "Depends of $deb lacks $dep: $depends"
  done
  dpkg-deb -x "$deb" "$tmp/root"
  "$tmp/root/usr/bin/dynid" model --robot puma560 >/dev/null || fail "the unpacked CLI"
  ;;
pip)
  build_dir=$3 python=$4
  DYNID_BUILD_DIR=$build_dir "$python" -m pip install --no-build-isolation --no-deps --no-index \
    --no-cache-dir --disable-pip-version-check -q --target "$tmp/site" "$source_dir" \
    >"$tmp/log" 2>&1 || fail "pip install: $(cat "$tmp/log")"
  add_probe_robot "$tmp/site/dynid/robots"
  cd "$tmp"
  PYTHONPATH=$tmp/site PYTHONDONTWRITEBYTECODE=1 "$python" -c "
import os, sys, dynid
assert dynid.__file__.startswith('$tmp/site/'), dynid.__file__
assert dynid.__version__, 'no version'
model = dynid.load_model('relocated_probe')
assert 'relocated_probe' in repr(model) and '2 joints' in repr(model), repr(model)
" || fail "import dynid from the installed package"
  ;;
*)
  fail "unknown mode; use prefix, subdirectory, deb or pip"
  ;;
esac
echo "ok ($mode)"
