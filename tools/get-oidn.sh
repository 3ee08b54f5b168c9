#!/usr/bin/env bash
# Installs Intel Open Image Denoise 2.5.1 for pathlight's denoiser (`render --denoise`,
# `pathlight denoise`, the viewer's D key): the four CPU libraries of the PyPI wheel `pyoidn`
# 2.5.1.0 (which bundles OIDN's official Linux build, Apache-2.0), about 54 MB, into
# DIR/lib. DIR defaults to where pathlight looks first: ${XDG_DATA_HOME:-~/.local/share}/pathlight/oidn.
# Elsewhere, point PATHLIGHT_OIDN at DIR. Needs python3 with pip and access to PyPI.
#
#   tools/get-oidn.sh [DIR]
set -euo pipefail

dest=${1:-${XDG_DATA_HOME:-$HOME/.local/share}/pathlight/oidn}
lib="$dest/lib"
if [ -f "$lib/libOpenImageDenoise.so.2" ]; then
    echo "Open Image Denoise is already in $lib"
    exit 0
fi
case "$(uname -s)-$(uname -m)" in
    Linux-x86_64) ;;
    *) echo "tools/get-oidn.sh fetches OIDN for Linux on x86-64; elsewhere install OIDN 2 from https://www.openimagedenoise.org and set PATHLIGHT_OIDN to its folder" >&2
       exit 1 ;;
esac
wheel=pyoidn-2.5.1.0-py3-none-manylinux2014_x86_64.whl
sha256=32ad13368f8de1ef63001942ad05b02a00cd732d1206d97f352d3a3f606d823e
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
python3 -m pip download --quiet --disable-pip-version-check --no-deps --only-binary=:all: \
    --platform manylinux2014_x86_64 --python-version 3.11 pyoidn==2.5.1.0 -d "$tmp"
echo "$sha256  $tmp/$wheel" | sha256sum --check --quiet
mkdir -p "$lib"
python3 - "$tmp/$wheel" "$lib" <<'PY'
import os, sys, zipfile
wheel, lib = sys.argv[1], sys.argv[2]
# The CPU device needs these four; OIDN finds its core and device modules beside the library.
names = ["libOpenImageDenoise.so.2", "libOpenImageDenoise_core.so.2.5.1",
         "libOpenImageDenoise_device_cpu.so.2.5.1", "libtbb.so.12"]
with zipfile.ZipFile(wheel) as z:
    for name in names:
        target = os.path.join(lib, name)
        with z.open("pyoidn/oidn/lib/" + name) as src, open(target + ".part", "wb") as out:
            out.write(src.read())
        os.chmod(target + ".part", 0o755)
        os.replace(target + ".part", target)
PY
echo "Open Image Denoise 2.5.1 installed in $lib"
