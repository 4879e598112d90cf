#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The gallery: renders every self-contained corpus model with its own cpfg command line
# and writes one HTML page that shows each render beside cpfg's window image
# (corpus/oracle/<id>/image.png, where the corpus has it).
#
#   scripts/gallery.sh [OUT_DIR] [extra cambium options...]
#
# OUT_DIR defaults to build/gallery; open OUT_DIR/index.html. The corpus is
# $CAMBIUM_CORPUS or ../shared/corpus; the binary $CAMBIUM or build/src/app/cambium.
# Default extra options: --spp 16 (a few seconds per model).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
out=$(realpath -m "${1:-$root/build/gallery}")
shift || true
extra=("$@")
[ ${#extra[@]} -eq 0 ] && extra=(--spp 16)
corpus=$(realpath "${CAMBIUM_CORPUS:-$root/../shared/corpus}")
cambium=$(realpath "${CAMBIUM:-$root/build/src/app/cambium}")
[ -x "$cambium" ] || { echo "gallery: build cambium first ($cambium)" >&2; exit 1; }
mkdir -p "$out/img"

# id, folder and cpfg's arguments of every model that needs no environmental program
python3 - "$corpus" > "$out/models.txt" <<'PY'
import json, pathlib, sys
corpus = pathlib.Path(sys.argv[1])
for f in sorted((corpus / "cpfg").rglob("model.json")):
    m = json.loads(f.read_text())
    if not m.get("env_program", False):
        # a still, as cpfg's window shows it: without -a (animate mode)
        args = [a for a in m["command"].split()[1:] if a != "-a"]
        print(m["id"], f.parent, *args, sep="\t")
PY

rows=""
while IFS=$'\t' read -r id folder args; do
  name=${id//\//__}
  IFS=$'\t' read -r -a words <<< "$args"
  status=ok
  ( cd "$folder" && "$cambium" "${words[@]}" "${extra[@]}" -q -o "$out/img/$name.png" < /dev/null ) \
      > "$out/img/$name.log" 2>&1 || status="failed (see img/$name.log)"
  cpfg="$corpus/oracle/$id/image.png"
  if [ -f "$cpfg" ]; then
    cp "$cpfg" "$out/img/$name.cpfg.png"
    theirs="<img src=\"img/$name.cpfg.png\">"
  else
    theirs="<i>no cpfg image in the corpus (held back)</i>"
  fi
  ours="<img src=\"img/$name.png\">"
  [ "$status" = ok ] || ours="<i>$status</i>"
  rows+="<tr><th colspan=2>$id <code>${words[*]}</code></th></tr><tr><td>$ours</td><td>$theirs</td></tr>"$'\n'
  echo "gallery: $id $status" >&2
done < "$out/models.txt"

cat > "$out/index.html" <<HTML
<!doctype html><meta charset="utf-8"><title>Cambium beside cpfg</title>
<style>body{font-family:sans-serif;background:#888}td{vertical-align:top}img{width:480px}th{text-align:left;padding-top:1em}</style>
<h1>Cambium (left) beside cpfg's window (right)</h1>
<p>cambium ${extra[*]}; corpus $corpus</p>
<table>
$rows</table>
HTML
echo "gallery: $out/index.html"
