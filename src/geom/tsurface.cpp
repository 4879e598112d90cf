// SPDX-License-Identifier: Apache-2.0
// Tsurfaces: triangles from rayshade-like text, as cpfg's tsurfaces.c reads them.
#include "geom/tsurface.h"

#include <array>
#include <charconv>
#include <cmath>

namespace cambium::geom {

namespace {

struct Token {
    std::string_view text;
    int column;
};

// cpfg splits tsurface lines with strtok(" \t,:\n").
std::vector<Token> split_tokens(std::string_view line)
{
    std::vector<Token> tokens;
    auto is_separator = [](char c) { return c == ' ' || c == '\t' || c == ',' || c == ':' || c == '\r'; };
    std::size_t i = 0;
    while (i < line.size()) {
        while (i < line.size() && is_separator(line[i]))
            ++i;
        std::size_t start = i;
        while (i < line.size() && !is_separator(line[i]))
            ++i;
        if (i > start)
            tokens.push_back({line.substr(start, i - start), static_cast<int>(start) + 1});
    }
    return tokens;
}

double parse_value(const Token& token, const FileLoc& loc)
{
    std::string_view t = token.text;
    if (!t.empty() && t.front() == '+')
        t.remove_prefix(1);
    double v = 0;
    auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
    if (ec != std::errc() || end != t.data() + t.size() || !std::isfinite(v))
        throw Error(loc, "expected a number in a tsurface triangle, not '" + std::string(token.text) + "'");
    return v;
}

struct Vertex {
    std::array<double, 8> values{};
    int count = 0;
};

Float3 as_float3(double x, double y, double z)
{
    return {static_cast<float>(x), static_cast<float>(y), static_cast<float>(z)};
}

void append_triangle(const std::array<Vertex, 3>& v, double scale, std::int16_t texture,
                     TriangleMesh& mesh)
{
    Vec3 p[3];
    for (int k = 0; k < 3; ++k)
        p[k] = Vec3{v[k].values[0], v[k].values[1], v[k].values[2]} * scale;
    Vec3 face = normalize(cross(p[1] - p[0], p[2] - p[0]));
    const auto base = static_cast<std::uint32_t>(mesh.positions.size());
    for (int k = 0; k < 3; ++k) {
        const auto& a = v[k].values;
        Vec3 n = normalize(Vec3{a[3], a[4], a[5]});
        if (length(n) == 0)
            n = face;
        mesh.positions.push_back(as_float3(p[k].x, p[k].y, p[k].z));
        mesh.normals.push_back(as_float3(n.x, n.y, n.z));
        mesh.uvs.push_back({static_cast<float>(a[6]), static_cast<float>(a[7])});
    }
    mesh.triangles.push_back({base, base + 1, base + 2});
    mesh.material.push_back(inherit_material);
    mesh.back_material.push_back(inherit_material);
    mesh.texture.push_back(texture);
}

}  // namespace

SurfaceDef parse_tsurface_text(std::string_view text, const std::string& file_name,
                               const SurfaceCommand& command)
{
    SurfaceDef def;
    def.letter = command.letter;
    def.name = command.file.stem().string();
    def.kind = SurfaceCommand::Kind::triangles;
    def.scale = command.scale;
    def.texture = command.texture;
    def.moves_turtle = false;  // cpfg's determine_end_point finds no bicubic surface
    def.prototype.name = std::string(1, command.letter);
    const std::int16_t texture = command.texture.value_or(no_texture);
    TriangleMesh& mesh = def.prototype.geometry.mesh;

    bool in_triangle = false;
    FileLoc triangle_loc;
    std::array<Vertex, 3> vertices{};
    int vertex = 0;
    int line_number = 0;
    std::size_t pos = 0;
    while (pos <= text.size()) {
        std::size_t end = text.find('\n', pos);
        if (end == std::string_view::npos)
            end = text.size();
        std::string_view line = text.substr(pos, end - pos);
        pos = end + 1;
        ++line_number;
        std::vector<Token> tokens = split_tokens(line);
        for (std::size_t i = 0; i < tokens.size(); ++i) {
            FileLoc loc{file_name, line_number, tokens[i].column};
            if (!in_triangle) {
                if (tokens[i].text.substr(0, 8) == "triangle") {
                    if (mesh.size() >= max_tsurface_triangles)
                        throw Error(loc, "too many tsurface triangles (the limit is " +
                                             std::to_string(max_tsurface_triangles) + ")");
                    in_triangle = true;
                    triangle_loc = loc;
                    vertex = 0;
                    vertices = {};
                }
                continue;
            }
            Vertex& v = vertices[static_cast<std::size_t>(vertex)];
            v.values[static_cast<std::size_t>(v.count)] = parse_value(tokens[i], loc);
            if (++v.count == 8)
                break;  // the rest of the line is ignored
        }
        if (in_triangle && vertices[static_cast<std::size_t>(vertex)].count >= 3) {
            if (++vertex == 3) {
                append_triangle(vertices, command.scale, texture, mesh);
                in_triangle = false;
            }
        }
    }
    if (in_triangle)
        throw Error(triangle_loc, "tsurface triangle unfinished at the end of the file");
    def.uvs_per_surface = mesh.uvs;
    return def;
}

}  // namespace cambium::geom
