#!/usr/bin/env bash
# Installs the Debian packages the test suite needs, only when they are missing.
# Each entry: "<command that proves it is installed>:<apt package>".
set -euo pipefail
NEEDED=(
  fuzzylite:fuzzylite  # fuzzylite 6.0 command: outside oracle for our FIS/FLL exports
  chromium:chromium    # the browser the studio tests drive (Playwright with executable_path)
  javac:default-jdk-headless  # Java: tests/engine/test_fdlibm.py checks fdlibm.py against StrictMath
  cc:build-essential   # C compiler and headers: the generated C and the native backend
  flex:flex            # flex, bison, autoconf, automake, libtool: the tests build matiec
  bison:bison          #   (OpenPLC's IEC 61131-3 compiler, extra suite "matiec") from source
  autoreconf:autoconf
  aclocal:automake
  libtoolize:libtool
)
missing=()
for entry in "${NEEDED[@]}"; do
  probe=${entry%%:*}
  pkg=${entry##*:}
  command -v "$probe" >/dev/null 2>&1 || missing+=("$pkg")
done
[ ${#missing[@]} -eq 0 ] && exit 0
SUDO=""
[ "$(id -u)" -ne 0 ] && SUDO="sudo"
echo "installing system packages: ${missing[*]}" >&2
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
