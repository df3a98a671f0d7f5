#!/usr/bin/env bash
# Installs pdflab's build, test and viewer dependencies from Debian 12's packages.
# Skips apt entirely when everything is already present, so repeated runs are fast.
set -euo pipefail

packages=(
  build-essential cmake pkg-config ninja-build   # ninja: scripts/configure.sh
  libglfw3-dev libimgui-dev libglm-dev libstb-dev python3-glad python3-jinja2
  nlohmann-json3-dev libcli11-dev libpcg-cpp-dev libmuparser-dev   # libmuparser: the 1D lab's typed f(x)
  libopenexr-dev openexr zlib1g-dev   # EXR output (openexr: exrheader, which a test reads our files with); film checksums
  parallel                             # scripts/render_parallel.sh fans a render out over job slots or machines
  libgtest-dev libbenchmark-dev
  universal-ctags   # a test that ctags finds the lane-generic definitions (.ctags.d)
  python3-dev pybind11-dev python3-numpy python3-pytest   # the Python module (python/) and its tests
  python3-matplotlib python3-ipykernel jupyter-nbconvert jupyter-notebook   # the notebooks: run in CI, opened by scripts/notebook.sh
  clang-14 libclang-rt-14-dev   # the fuzzer: clang's libFuzzer and sanitizer runtimes (a recommend, not a dependency)
  xvfb xauth mesa-utils libgl1-mesa-dri xdotool imagemagick x11-apps xclip
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi

echo "Installing: ${missing[*]}"
sudo_cmd=()
[ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
"${sudo_cmd[@]}" apt-get update -qq
DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
