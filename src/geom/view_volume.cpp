// SPDX-License-Identifier: Apache-2.0
// cpfg's view-volume file (-vv): the bounding box of the interpreted geometry.
#include "geom/view_volume.h"

#include <cstdio>
#include <fstream>
#include <regex>
#include <system_error>

#include "base/atomic_file.h"
#include "base/diagnostics.h"

namespace cambium::geom {

std::string format_view_volume(const Bounds3& box)
{
    Bounds3 b = box;
    if (b.empty())
        b.extend(Vec3{0, 0, 0});
    char line[256];
    std::snprintf(line, sizeof line, "box: x: %g,%g y: %g,%g z: %g,%g", b.lo.x, b.hi.x, b.lo.y,
                  b.hi.y, b.lo.z, b.hi.z);
    return line;
}

void write_view_volume(const Bounds3& box, const std::filesystem::path& file)
{
    write_file_atomically(file, [&](const std::filesystem::path& temporary) {
        std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
        out << format_view_volume(box) << '\n';
        out.close();
        if (!out)
            throw Error(FileLoc{file.string()}, "cannot write the view volume file");
    });
}

Bounds3 parse_view_volume(std::string_view text, const std::string& file_name)
{
    static const std::regex syntax(
        R"(\s*box:\s*x:\s*(\S+?)\s*,\s*(\S+)\s+y:\s*(\S+?)\s*,\s*(\S+)\s+z:\s*(\S+?)\s*,\s*(\S+)\s*)");
    std::string line(text.substr(0, text.find('\n')));
    std::smatch m;
    if (!std::regex_match(line, m, syntax))
        throw Error(FileLoc{file_name, 1, 1},
                    "expected 'box: x: min,max y: min,max z: min,max'");
    double v[6];
    for (int i = 0; i < 6; ++i) {
        try {
            v[i] = std::stod(m[i + 1].str());
        } catch (const std::exception&) {
            throw Error(FileLoc{file_name, 1, static_cast<int>(m.position(i + 1)) + 1},
                        "'" + m[i + 1].str() + "' is not a number");
        }
    }
    Bounds3 b;
    b.extend(Vec3{v[0], v[2], v[4]});
    b.extend(Vec3{v[1], v[3], v[5]});
    return b;
}

}  // namespace cambium::geom
