// SPDX-License-Identifier: Apache-2.0
#include "geom/gls_polygons.h"

#include <cstdio>

namespace cambium::geom {

void append_polygons_since(const Scene& scene, const GeometryMark& since,
                           std::vector<GlsPolygon>& out)
{
    TriangleMesh mesh;
    tessellate_since(scene, since, gls_tessellation, mesh);
    for (const auto& t : mesh.triangles) {
        GlsPolygon p;
        for (std::uint32_t i : t)
            p.push_back(Vec3{mesh.positions[i][0], mesh.positions[i][1], mesh.positions[i][2]});
        out.push_back(std::move(p));
    }
}

std::string gls_polygon_statement(const GlsPolygon& polygon)
{
    std::string text = "polygon";
    char number[32];
    for (const Vec3& v : polygon)
        for (double x : {v.x, v.y, v.z}) {
            std::snprintf(number, sizeof number, " %g", x);
            text += number;
        }
    return text;
}

}  // namespace cambium::geom
