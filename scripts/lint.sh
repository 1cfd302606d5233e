#!/usr/bin/env bash
# The linters the style guide names: ruff (lint and format) and mypy (types), as CI runs them.
set -euo pipefail
cd "$(dirname "$0")/.."
.venv/bin/ruff check src tests bench scripts
.venv/bin/ruff format --check src tests
.venv/bin/mypy
