#!/usr/bin/env bash
# Installs the Debian 12 packages substratec needs, if any is missing.
# Nothing else is downloaded: every dependency is a Debian package.
set -euo pipefail

PACKAGES=(
  cmake ninja-build g++ python3 python3-jsonschema
  nlohmann-json3-dev libfmt-dev libcli11-dev libgtest-dev libbenchmark-dev
  glslang-dev glslang-tools spirv-tools
  libvulkan-dev mesa-vulkan-drivers vulkan-validationlayers vulkan-tools libpng-dev
  libjpeg62-turbo-dev   # texture images: JPEG (PNG is libpng's)
  libstb-dev            # Radiance HDR environments (stb_image's header)
  clang-14 libclang-rt-14-dev llvm-14   # scripts/fuzz.sh: libFuzzer, ASan/UBSan runtimes, llvm-symbolizer
  libpugixml-dev
  libxxhash-dev
  bazel-bootstrap       # tests/bazel_example: the persistent worker under Debian's Bazel 4 (a headless JDK with it)
  chromium tidy         # tests/html: the HTML report in headless Chromium, checked by HTML Tidy
)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi
echo "deps: installing ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null; then SUDO=sudo; else
    echo "deps: missing packages (${missing[*]}) and not root; install them or run as root" >&2
    exit 1
  fi
fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
