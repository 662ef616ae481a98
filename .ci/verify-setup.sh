#!/usr/bin/env bash
# Installs what tests/verify/verify_outputs.py needs: Chromium, xmllint and the shared
# libraries that the gmsh wheel links (apt, only if missing) and the Python readers in
# .venv-verify (pinned in tests/verify/requirements.txt); and what the browser test of the
# report's 3D viewer needs: node and playwright-core in tests/browser/node_modules (`npm ci`
# from the committed package-lock.json).
# Idempotent: a second run changes nothing and says so.
set -euo pipefail
cd "$(dirname "$0")/.."

missing=()
command -v chromium >/dev/null 2>&1 || missing+=(chromium)
command -v xmllint >/dev/null 2>&1 || missing+=(libxml2-utils)
command -v node >/dev/null 2>&1 || missing+=(nodejs npm)
python3 -c 'import ensurepip, venv' >/dev/null 2>&1 || missing+=(python3-venv)
# The gmsh wheel's libgmsh links X11, OpenGL/GLU, Xft and fontconfig (ldd libgmsh.so.4.15).
# (Skipped where there is no ldconfig cache to ask.)
ldcache=$({ ldconfig -p || /sbin/ldconfig -p; } 2>/dev/null || true)
[ -n "$ldcache" ] && for pair in libGLU.so.1:libglu1-mesa libGL.so.1:libgl1 libX11.so.6:libx11-6 libXext.so.6:libxext6 \
  libXrender.so.1:libxrender1 libXcursor.so.1:libxcursor1 libXfixes.so.3:libxfixes3 \
  libXft.so.2:libxft2 libXinerama.so.1:libxinerama1 libfontconfig.so.1:libfontconfig1 \
  libgomp.so.1:libgomp1; do
  grep -q "${pair%%:*} " <<<"$ldcache" || missing+=("${pair#*:}")
done
if ((${#missing[@]})); then
  echo "verify-setup: apt-get install ${missing[*]}"
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${missing[@]}" >/dev/null
else
  echo "verify-setup: chromium, xmllint and gmsh's libraries already installed"
fi

req=tests/verify/requirements.txt
req_any=tests/verify/requirements-any-python.txt
stamp=.venv-verify/.requirements.sha256
want=$(cat "$req" "$req_any" | sha256sum | cut -d' ' -f1)
if [ -x .venv-verify/bin/python ] && [ "$(cat "$stamp" 2>/dev/null)" = "$want" ]; then
  echo "verify-setup: .venv-verify up to date with $req"
else
  echo "verify-setup: creating .venv-verify and installing $req"
  python3 -m venv .venv-verify
  .venv-verify/bin/pip install -q --disable-pip-version-check -r "$req"
  .venv-verify/bin/pip install -q --disable-pip-version-check --no-deps --ignore-requires-python -r "$req_any"
  # The gmsh wheel loads its library at import: fail here, naming what is missing.
  if ! .venv-verify/bin/python -c 'import gmsh' >/dev/null 2>&1; then
    echo "verify-setup: gmsh does not load: $(ldd .venv-verify/lib/libgmsh.so* 2>&1 | grep 'not found' | tr -s ' \n' ' ')" >&2
    exit 1
  fi
  echo "$want" > "$stamp"
fi
# The Khronos glTF-Validator (npm, pinned by tests/verify/gltf/package-lock.json).
gl=tests/verify/gltf; glwant=$(sha256sum "$gl/package-lock.json" | cut -d' ' -f1)
if [ -d "$gl/node_modules/gltf-validator" ] && [ "$(cat "$gl/node_modules/.lock.sha256" 2>/dev/null)" = "$glwant" ]; then
  echo "verify-setup: gltf-validator up to date with $gl/package-lock.json"
else
  echo "verify-setup: npm ci in $gl"; (cd "$gl" && npm ci --no-audit --no-fund --silent) && echo "$glwant" > "$gl/node_modules/.lock.sha256"
fi
# playwright-core for tests/browser (crates/terramesh-cli/tests/report_viewer.rs).
node_major=$(node -p 'process.versions.node.split(".")[0]')
if [ "$node_major" -lt 20 ]; then
  echo "verify-setup: node $(node --version) is too old for playwright-core (needs 20 or newer)" >&2
  exit 1
fi
lock=tests/browser/package-lock.json
nstamp=tests/browser/node_modules/.package-lock.sha256
nwant=$(sha256sum "$lock" | cut -d' ' -f1)
if [ "$(cat "$nstamp" 2>/dev/null)" = "$nwant" ]; then
  echo "verify-setup: tests/browser/node_modules up to date with $lock"
else
  echo "verify-setup: npm ci in tests/browser"
  (cd tests/browser && npm ci --no-audit --no-fund --silent)
  echo "$nwant" > "$nstamp"
fi
echo "verify-setup: done ($(.venv-verify/bin/python --version), $(xmllint --version 2>&1 | head -1), $(chromium --version 2>/dev/null), gmsh $(.venv-verify/bin/python -c 'import gmsh; print(gmsh.__version__)'), node $(node --version))"
# OpenGeoSys' programs from the ogs wheel (in .venv-verify since requirements.txt pins it; about
# 30 s to download and install alone): the geological model's checks run `ogs`, ExtractBoundary
# and checkMesh (tests/verify/check_model.py). Fail here, naming the one that does not start.
for tool in ogs ExtractBoundary checkMesh; do
  if ! .venv-verify/bin/$tool --version >/dev/null 2>&1; then
    echo "verify-setup: OpenGeoSys' $tool does not start: $(.venv-verify/bin/$tool --version 2>&1 | tail -1)" >&2
    exit 1
  fi
done
echo "verify-setup: OpenGeoSys $(.venv-verify/bin/ogs --version 2>&1 | grep -o 'version: [0-9.]*') with ExtractBoundary and checkMesh"
