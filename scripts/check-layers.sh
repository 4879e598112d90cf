#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Fails when a file in src/ includes what its layer may not see (a quick ctest):
#   base    the standard library (and POSIX headers) only
#   lsys    + base
#   geom    + lsys; never Embree, TBB, OpenImageIO or render
#   env     + geom (open L-systems' environments); never Embree, TBB, OpenImageIO or render
#   render  + geom/scene.h, geom/primitives.h, geom/scene_limits.h, geom/line_ends.h and geom/vec.h
#           (the Scene contract), Embree, TBB, FreeType and fontconfig (labels), cairo (vector outputs)
#   imageio what render may + render + OpenImageIO (libcambium_imageio.so: the only OpenImageIO user)
#   app     everything
#   python  + app (the command's pipeline) and pybind11: the Python module
# Standard and POSIX headers are <name>, <name.h> and <sys/name.h>; any other <dir/...> is a
# third-party library; "layer/file.h" is the project's own.
#   scripts/check-layers.sh [SRC]   (default: the src/ beside this script)
set -euo pipefail
src=${1:-$(cd "$(dirname "$0")/.." && pwd)/src}
cd "$src"
find . -type f \( -name '*.h' -o -name '*.cpp' -o -name '*.def' \) | sort \
    | xargs awk '
BEGIN {
    project["base"] = "^base/"
    project["lsys"] = "^(base|lsys)/"
    project["geom"] = "^(base|lsys|geom)/"
    project["env"] = "^(base|lsys|geom|env)/"
    project["render"] = "^(base|render)/|^geom/(scene|primitives|scene_limits|line_ends|vec)\\.h$"
    project["imageio"] = "^(base|render|imageio)/|^geom/(scene|primitives|scene_limits|line_ends|vec)\\.h$"
    project["app"] = "."
    project["python"] = "^(base|lsys|geom|env|render|app)/"
    library["render"] = "^(embree3|tbb|fontconfig)/|^ft2build\\.h$|^cairo(-[a-z]+)?\\.h$"
    library["imageio"] = "^(tbb|OpenImageIO)/"
    library["app"] = "."
    library["python"] = "^pybind11/"
    rule["base"] = "the standard library only"
    rule["lsys"] = "the standard library and base only"
    rule["geom"] = "the standard library, base and lsys only"
    rule["env"] = "the standard library, base, lsys and geom only"
    rule["render"] = "base, geom/scene.h, geom/primitives.h, geom/scene_limits.h, geom/line_ends.h, geom/vec.h, Embree, TBB, FreeType, fontconfig and cairo only"
    rule["imageio"] = "base, render, the Scene contract, TBB and OpenImageIO only"
    rule["app"] = "anything"
    rule["python"] = "the project layers and pybind11 only"
}
FNR == 1 {
    file = FILENAME; sub(/^\.\//, "", file)
    layer = file; sub(/\/.*/, "", layer)
    if (!(layer in rule) && !(layer in unknown)) {
        printf "src/%s: no include rule for layer %s: add one to scripts/check-layers.sh\n", file, layer
        unknown[layer] = 1; bad = 1
    }
}
/^[ \t]*#[ \t]*include/ {
    line = $0
    sub(/^[ \t]*#[ \t]*include[ \t]*/, "", line)
    if (line ~ /^"/) {
        name = substr(line, 2); sub(/".*/, "", name)
        ok = name ~ project[layer]
    } else {
        name = substr(line, 2); sub(/>.*/, "", name)
        ok = name ~ /^[A-Za-z0-9_]+(\.h)?$/ || name ~ /^sys\/[A-Za-z0-9_]+\.h$/ \
             || (layer in library && name ~ library[layer])
    }
    if (!ok) {
        printf "src/%s:%d: %s may include %s; not %s\n", file, FNR, layer, rule[layer], name
        bad = 1
    }
}
END {
    if (bad) exit 1
    print "check-layers: every layer includes only what it may"
}'
