#!/usr/bin/env bash
# Installs the Debian 12 packages eamos needs, only those missing: `apt-get update`
# once, then `apt-get install -y`. Safe to run again; does nothing when all are there.
set -euo pipefail

# `install-deps.sh demo`: only what `make demo` needs to build the `eamos` command and run it
# (compiler, libraries, Graphviz, Cyclone DDS; GoogleTest and Google Benchmark because the build
# configures the tests too, without building them). Without an argument: everything `make
# test` needs as well.
demo_packages=(
  build-essential cmake ninja-build pkg-config
  libfmt-dev libyaml-cpp-dev nlohmann-json3-dev libcli11-dev nettle-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  graphviz
  libcivetweb-dev
  cyclonedds-dev cyclonedds-tools libddsc0debian libssl-dev openssl
)
test_packages=(
  clang libclang-rt-14-dev
  nodejs
  chromium
  iproute2  # ip netns and veth pairs for tests/launch/netns_test.cpp
  vim vim-ale neovim  # tests/lsp: editors/vim in vim -es, eamos lsp through ALE and Neovim's LSP client
  help2man  # the man pages, made from --help at build time (packaging/man_pages.cmake)
  # tests/install: the .deb's Depends (dpkg-shlibdeps, in dpkg-dev), the rendered man pages,
  # the zsh completion, the DEX's unit (systemd-analyze verify)
  dpkg-dev man-db zsh systemd
  python3-dev python3-pybind11  # the Python module (src/python), built against Debian's /usr/bin/python3
  python3-pytest python3-matplotlib python3-pandas  # test side: tests/python (the module needs neither at run time)
)
packages=("${demo_packages[@]}")
if [ "${1:-}" != demo ]; then packages+=("${test_packages[@]}"); fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
# npm (test-side tools only: node-mavlink for the MAVLink cross-check) is checked by command,
# not by package: a NodeSource nodejs bundles npm and conflicts with Debian's npm package.
if [ "${1:-}" != demo ] && ! command -v npm >/dev/null 2>&1; then
  missing+=(npm)
fi

if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -q
$SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
