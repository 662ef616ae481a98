#!/usr/bin/env bash
# Installs what tests/verify/verify_outputs.py needs: Chromium and xmllint (apt, only if
# missing) and the Python readers in .venv-verify (pinned in tests/verify/requirements.txt).
# Idempotent: a second run changes nothing and says so.
set -euo pipefail
cd "$(dirname "$0")/.."

missing=()
command -v chromium >/dev/null 2>&1 || missing+=(chromium)
command -v xmllint >/dev/null 2>&1 || missing+=(libxml2-utils)
python3 -c 'import ensurepip, venv' >/dev/null 2>&1 || missing+=(python3-venv)
if ((${#missing[@]})); then
  echo "verify-setup: apt-get install ${missing[*]}"
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${missing[@]}" >/dev/null
else
  echo "verify-setup: chromium and xmllint already installed"
fi

req=tests/verify/requirements.txt
stamp=.venv-verify/.requirements.sha256
want=$(sha256sum "$req" | cut -d' ' -f1)
if [ -x .venv-verify/bin/python ] && [ "$(cat "$stamp" 2>/dev/null)" = "$want" ]; then
  echo "verify-setup: .venv-verify up to date with $req"
else
  echo "verify-setup: creating .venv-verify and installing $req"
  python3 -m venv .venv-verify
  .venv-verify/bin/pip install -q --disable-pip-version-check -r "$req"
  echo "$want" > "$stamp"
fi
echo "verify-setup: done ($(.venv-verify/bin/python --version), $(xmllint --version 2>&1 | head -1), $(chromium --version 2>/dev/null))"
