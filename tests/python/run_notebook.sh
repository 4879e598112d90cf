#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Executes the example notebook with Jupyter's nbconvert (Debian's jupyter-nbconvert and
# python3-ipykernel); a cell that raises fails the test. Skipped (77) without Jupyter or
# without the corpus the notebook loads.
#   run_notebook.sh PYTHON NOTEBOOK OUTPUT_FOLDER
set -euo pipefail
python=$1 notebook=$2 out=$3
if ! "$python" -c "import nbconvert, ipykernel" 2>/dev/null; then
    echo "skipped: nbconvert or ipykernel is not installed (scripts/setup.sh installs them)"
    exit 77
fi
corpus=${CAMBIUM_CORPUS:-${CAMBIUM_CORPUS_DEFAULT:-}}
if [ ! -d "$corpus/cpfg" ]; then
    echo "skipped: the model corpus is not there (../shared/corpus or \$CAMBIUM_CORPUS)"
    exit 77
fi
export CAMBIUM_CORPUS=$corpus PYDEVD_DISABLE_FILE_VALIDATION=1
mkdir -p "$out"
"$python" -m nbconvert --to notebook --execute --ExecutePreprocessor.timeout=300 \
    --output-dir "$out" "$notebook"
