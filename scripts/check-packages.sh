#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Fails when the build or the tests use a file from a Debian package that scripts/setup.sh
# does not install, by itself or through a hard Depends (Recommends do not count: setup
# installs without them). The files: BUILD/package-files.txt (cmake/PackageFiles.cmake:
# the tools, each found package's CMake files, every file its imported targets name) and
# every system header the compiler read (the *.o.d dependency files of the build).
# Files of imported targets the build does not link need to come from a listed package only
# when the package that has them does not define those targets itself: Debian's
# libopenimageio-dev defines OpenImageIO::iconvert, whose /usr/bin/iconvert comes from
# openimageio-tools, and its CMake package stops the configure when that file is missing.
#   scripts/check-packages.sh BUILD                 the check (a quick ctest)
#   scripts/check-packages.sh --without PKG BUILD   the same with PKG left out of the list
# Exit 0: all listed; 1: a file comes from an unlisted package or none; 77: not Debian.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
without=""
if [ "${1:-}" = "--without" ]; then without=$2; shift 2; fi
build=$(cd "${1:?usage: check-packages.sh [--without PKG] BUILD}" && pwd)
command -v dpkg-query >/dev/null || { echo "check-packages: no dpkg, not checked"; exit 77; }
[ -f "$build/package-files.txt" ] || { echo "check-packages: $build/package-files.txt missing (configure first)" >&2; exit 1; }

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

bash "$root/scripts/setup.sh" --list | grep -vxF -e "$without" > "$work/listed" || true

# "<who>\t<path>" for every file: the configure-time list, then the headers compiled against.
cp "$build/package-files.txt" "$work/needed"
find "$build" -name '*.o.d' -exec cat {} + 2>/dev/null | tr ' \\' '\n\n' | grep '^/' \
    | grep -v -e "^$root/" -e "^$build/" -e ':$' | sort -u | sed 's/^/headers the compiler read\t/; s/$/\tused/' \
    >> "$work/needed" || true
cut -f2 "$work/needed" | sort -u > "$work/paths"
while IFS= read -r path; do [ -e "$path" ] || echo "$path"; done < "$work/paths" > "$work/absent"

# Owning packages, "<pkg>[, <pkg>...]\t<path>"; a path dpkg does not know is tried again as
# the file it links to (alternatives such as /usr/bin/c++) and across the merged /usr.
split_owners() { grep -v '^diversion' | awk '{ i = index($0, ": /"); print substr($0, 1, i - 1) "\t" substr($0, i + 2) }' || true; }
owners_of() { xargs -d '\n' -a "$1" sh -c 'dpkg-query -S "$@" 2>/dev/null || true' sh | split_owners; }
owners_of "$work/paths" > "$work/owners"
cut -f2 "$work/owners" | sort -u | comm -23 "$work/paths" - | while IFS= read -r path; do
    for other in "$(realpath -m "$path")" "${path#/usr}" "/usr$path"; do
        [ "$other" != "$path" ] && printf '%s\t%s\n' "$other" "$path"
    done
done > "$work/aliases"
cut -f1 "$work/aliases" > "$work/alias_paths"
owners_of "$work/alias_paths" > "$work/alias_owners"
awk -F'\t' 'NR == FNR { owner[$2] = $1; next }
             { if (!($2 in found)) found[$2] = ""; if (found[$2] == "" && ($1 in owner)) found[$2] = owner[$1] }
             END { for (path in found) print found[path] "\t" path }' \
    "$work/alias_owners" "$work/aliases" >> "$work/owners"

# Packages that bring their own CMake targets (such as libgmock-dev): targets they define
# exist only with them, so their files are needed only when the build links those targets.
{ dpkg-query -S '*.cmake' 2>/dev/null || true; } | split_owners | cut -f1 | tr ',' '\n' \
    | sed 's/^ *//; s/:.*//' | sort -u > "$work/own_targets"

# Installed packages with what they provide and hard-depend on.
dpkg-query -W -f='${Package}\t${db:Status-Abbrev}\t${Provides}\t${Pre-Depends}, ${Depends}\n' \
    > "$work/installed"

awk -F'\t' -v listed="$work/listed" -v installed="$work/installed" -v owners="$work/owners" \
    -v absent="$work/absent" -v own_targets="$work/own_targets" '
function bare(name) { sub(/^ +/, "", name); sub(/ .*/, "", name); sub(/:.*/, "", name); return name }
BEGIN {
    while ((getline line < installed) > 0) {
        split(line, f, "\t")
        if (f[2] !~ /^ii/) continue
        ok[f[1]] = 1; deps[f[1]] = f[4]
        n = split(f[3], prov, ","); for (i = 1; i <= n; i++) providers[bare(prov[i])] = providers[bare(prov[i])] " " f[1]
    }
    # Everything a listed package brings with it through Depends and Pre-Depends.
    while ((getline p < listed) > 0) { if (p == "") continue; queue[++tail] = p; if (!ok[p]) notinst[p] = 1 }
    for (head = 1; head <= tail; head++) {
        p = queue[head]
        if (p in reach) continue
        reach[p] = 1
        n = split(deps[p], group, ",")
        for (i = 1; i <= n; i++) {
            m = split(group[i], alt, "|")
            for (j = 1; j <= m; j++) {
                d = bare(alt[j]); if (d == "") continue
                if (ok[d]) queue[++tail] = d
                k = split(providers[d], real, " "); for (r = 1; r <= k; r++) queue[++tail] = real[r]
            }
        }
    }
    for (p in notinst) { printf "check-packages: %s is listed in scripts/setup.sh but not installed\n", p; bad = 1 }
    while ((getline line < absent) > 0) gone[line] = 1
    while ((getline line < own_targets) > 0) self_contained[line] = 1
    while ((getline line < owners) > 0) {
        split(line, f, "\t")
        if (f[1] == "") { unowned[f[2]] = 1; continue }
        n = split(f[1], pkg, ","); good = 0
        for (i = 1; i <= n; i++) if (bare(pkg[i]) in reach) good = 1
        if (!good) from[f[2]] = bare(pkg[1])
    }
}
{
    if ($2 in gone) { printf "check-packages: %s (%s) does not exist\n", $2, $1; bad = 1; next }
    if ($2 in unowned) { printf "check-packages: %s (%s) is in no Debian package\n", $2, $1; bad = 1 }
    if (($2 in from) && !($3 == "defined" && self_contained[from[$2]])) {
        printf "check-packages: %s (%s) comes from %s, which scripts/setup.sh does not install\n", $2, $1, from[$2]
        missing[from[$2]] = 1; bad = 1
    }
}
END {
    for (p in missing) printf "check-packages: add %s to packages=(...) in scripts/setup.sh\n", p
    if (bad) exit 1
    print "check-packages: every file the build uses comes from a package scripts/setup.sh installs"
}' "$work/needed"
