#!/usr/bin/env bash
# Gradescope runs this once, as root, when it builds the autograder's image
# (base image: Ubuntu 22.04). It installs Python 3.11 and, into a virtual
# environment, fossbot-hil with its pinned, hash-checked dependencies: the
# ROS 2 Jazzy wheels among them, so no system ROS is needed. README.md
# explains each value; the defaults fit Gradescope.
set -euo pipefail

ROOT="${AUTOGRADER_ROOT:-/autograder}"
# fossbot-hil's release, copied into the autograder zip as fossbot-hil/.
SOURCE="${FOSSBOT_HIL_SOURCE:-$ROOT/source/fossbot-hil}"
VENV="${FOSSBOT_HIL_VENV:-$ROOT/fossbot-hil-venv}"
PYTHON="${FOSSBOT_HIL_PYTHON:-python3.11}"  # what the lock (requirements/ci.txt) is for

if [ ! -f "$SOURCE/pyproject.toml" ]; then
  echo "setup.sh: no fossbot-hil in $SOURCE: put its release into the zip as fossbot-hil/" >&2
  exit 1
fi

if [ ! -x "$VENV/bin/python" ]; then
  if ! command -v "$PYTHON" >/dev/null; then
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    apt-get install -y -qq --no-install-recommends python3.11 python3.11-venv ca-certificates
  fi
  "$PYTHON" -m venv "$VENV"
fi

# Every dependency at the release's pinned version and file hash (no resolving),
# then fossbot-hil itself, built with the pinned setuptools, asking the index nothing.
"$VENV/bin/python" -m pip install --quiet --require-hashes --no-deps -r "$SOURCE/requirements/ci.txt"
"$VENV/bin/python" -m pip install --quiet --no-build-isolation --no-deps "$SOURCE"

# Prove the image can run a node over ROS 2: the reference node, one scenario.
"$VENV/bin/python" -m harness.cli --version
"$VENV/bin/python" -m harness.cli run approach_wall --timeout 5 --ready-timeout 120
