#!/usr/bin/env bash
# Peer benchmark of unfold against Exudyn (see README.md).
# Creates bench/peer/.venv if missing, installs requirements.txt into it,
# then runs run.py with the arguments given (run.sh --help lists them).
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
venv="$here/.venv"
py="$venv/bin/python"

if [ ! -x "$py" ]; then
    echo "creating $venv"
    python3 -m venv "$venv"
fi
# Install only when the pinned versions are not all there (idempotent, no network when they are).
if ! "$py" - "$here/requirements.txt" <<'PY' 2>/dev/null
import sys
from importlib.metadata import version, PackageNotFoundError
for line in open(sys.argv[1]):
    line = line.split("#")[0].strip()
    if not line:
        continue
    name, want = line.split("==")
    try:
        if version(name) != want:
            sys.exit(1)
    except PackageNotFoundError:
        sys.exit(1)
PY
then
    echo "installing $(grep -v '^#' "$here/requirements.txt" | tr '\n' ' ')into $venv"
    "$py" -m pip install --quiet --disable-pip-version-check -r "$here/requirements.txt"
fi

cd "$here"
exec "$py" run.py "$@"
