// SPDX-License-Identifier: Apache-2.0
// Tests of predefined surfaces (.s), tsurfaces and their placement, with hand values and
// the cpfg oracle's rayshade output.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "geom/surface.h"
#include "geom/text_input.h"
#include "geom/tsurface.h"
#include "geom/view_file.h"
#include "test_util.h"

using namespace cambium;
using namespace cambium::geom;

namespace {

std::string neighbours(const std::string& l = "~", const std::string& r = "~")
{
    return "AL: ~ A: ~ AR: ~\nL: " + l + " R: " + r + "\nBL: ~ B: ~ BR: ~\n";
}

// One patch whose control point (i, j) is p(i, j).
template <class F>
std::string patch_text(const std::string& name, F p, const std::string& l = "~",
                       const std::string& r = "~")
{
    std::ostringstream s;
    s << name << "\nTOP COLOR: 0 DIFFUSE: 0.00 BOTTOM COLOR: 0 DIFFUSE: 0.00\n" << neighbours(l, r);
    for (int i = 0; i < 4; ++i) {
        for (int j = 0; j < 4; ++j) {
            Vec3 v = p(i, j);
            s << v.x << ' ' << v.y << ' ' << v.z << "  ";
        }
        s << '\n';
    }
    return s.str();
}

std::string header(Vec3 contact, Vec3 end, Vec3 heading, Vec3 up, double size,
                   const std::string& precision = "")
{
    std::ostringstream s;
    s << "0 1 0 1 0 0\n" << precision << "CONTACT POINT  X: " << contact.x << " Y: " << contact.y
      << " Z: " << contact.z << "\nEND POINT  X: " << end.x << " Y: " << end.y << " Z: " << end.z
      << "\nHEADING  X: " << heading.x << " Y: " << heading.y << " Z: " << heading.z
      << "\nUP  X: " << up.x << " Y: " << up.y << " Z: " << up.z << "\nSIZE: " << size << "\n";
    return s.str();
}

Vec3 unit_square(int i, int j) { return {j / 3.0, i / 3.0, 0}; }

SurfaceCommand command(char letter, double scale, int s = 0, int t = 0)
{
    SurfaceCommand c;
    c.letter = letter;
    c.file = std::string(1, letter) + ".s";
    c.scale = scale;
    c.s_steps = s;
    c.t_steps = t;
    return c;
}

Vec3 transform(const std::array<float, 12>& m, const Vec3& p)
{
    return {m[0] * p.x + m[3] * p.y + m[6] * p.z + m[9], m[1] * p.x + m[4] * p.y + m[7] * p.z + m[10],
            m[2] * p.x + m[5] * p.y + m[8] * p.z + m[11]};
}

const Float3* find_vertex(const TriangleMesh& mesh, const Vec3& p, double eps, std::size_t* index = nullptr)
{
    for (std::size_t i = 0; i < mesh.positions.size(); ++i)
        if (length(v3(mesh.positions[i]) - p) < eps) {
            if (index)
                *index = i;
            return &mesh.positions[i];
        }
    return nullptr;
}

}  // namespace

TEST(Surface, FlatUnitSquarePlacesAsHandComputed)
{
    std::string text = header({0.5, 0, 0}, {0.5, 1, 0}, {0, 1, 0}, {0, 0, 1}, 2) +
                       patch_text("square", unit_square);
    SurfaceDef def = parse_surface_text(text, "sq.s", command('q', 4, 3, 3));
    // scale / SIZE = 2; H = +y, U = +z, so L = H x U = +x and q = 2 (p - contact).
    const TriangleMesh& mesh = def.prototype.geometry.mesh;
    EXPECT_EQ(mesh.size(), 2u * 3u * 3u);
    EXPECT_NE(find_vertex(mesh, {-1, 0, 0}, 1e-5), nullptr);
    EXPECT_NE(find_vertex(mesh, {1, 2, 0}, 1e-5), nullptr);
    expect_near(def.local_end_point, {0, 2, 0}, 1e-12);
    for (const Float3& n : mesh.normals)
        expect_near(v3(n), {0, 0, 1}, 1e-6);
    EXPECT_EQ(mesh.material[0], inherit_material);
    EXPECT_EQ(mesh.back_material[0], inherit_material);
    EXPECT_EQ(mesh.texture[0], no_texture);

    // The turtle at (10, 0, 0) with H = +z, L = +y, U = L x H = +x.
    Vec3 pos{10, 0, 0}, H{0, 0, 1}, L{0, 1, 0}, U{1, 0, 0};
    auto m = surface_instance_transform(def, pos, H, L, U, {1, 1, 1});
    expect_near(transform(m, {1, 2, 0}), {10, 1, 2}, 1e-6);   // pos + 1 L + 2 H
    expect_near(transform(m, {-1, 0, 0}), {10, -1, 0}, 1e-6);
    expect_near(transform(m, {0, 0, 1}), {11, 0, 0}, 1e-6);   // + U
    expect_near(surface_end_position(def, pos, H, L, U, 1), {10, 0, 2}, 1e-12);
    // Non-uniform scale: per axis of the prototype (L, H, U); the end point uses sx only.
    auto m2 = surface_instance_transform(def, pos, H, L, U, {2, 3, 4});
    expect_near(transform(m2, {1, 2, 1}), {10 + 4, 2, 6}, 1e-6);
    expect_near(surface_end_position(def, pos, H, L, U, 2), {10, 0, 4}, 1e-12);
}

TEST(Surface, FileFrameMapsXToLeftYToHeadingZToUp)
{
    // H = +z, U = +y: L = H x U = -x, U' = L x H = +y; q = x L + y H + z U' = (-x, z, y).
    std::string text = header({0, 0, 0}, {1, 2, 3}, {0, 0, 1}, {0, 1, 0}, 1) +
                       patch_text("p", unit_square);
    SurfaceDef def = parse_surface_text(text, "f.s", command('f', 1));
    expect_near(def.local_end_point, {-1, 3, 2}, 1e-12);
    EXPECT_NE(find_vertex(def.prototype.geometry.mesh, {-1, 0, 1}, 1e-5), nullptr);  // p = (1, 1, 0)
}

TEST(Surface, PrecisionFromFileViewAndDefault)
{
    std::string body = patch_text("p", unit_square);
    SurfaceDef a = parse_surface_text(header({}, {}, {0, 1, 0}, {0, 0, 1}, 1) + body, "a.s", command('a', 1));
    EXPECT_EQ(a.s_steps, 5);
    EXPECT_EQ(a.t_steps, 5);
    // cpfg takes the T precision from S as well.
    SurfaceDef b = parse_surface_text(
        header({}, {}, {0, 1, 0}, {0, 0, 1}, 1, "PRECISION S: 3 T: 7\n") + body, "b.s", command('b', 1));
    EXPECT_EQ(b.s_steps, 3);
    EXPECT_EQ(b.t_steps, 3);
    SurfaceDef c = parse_surface_text(
        header({}, {}, {0, 1, 0}, {0, 0, 1}, 1, "PRECISION S: 3 T: 7\n") + body, "c.s", command('c', 1, 2, 4));
    EXPECT_EQ(c.prototype.geometry.mesh.size(), 2u * 2u * 4u);
}

TEST(Surface, SeamNormalsAreAveraged)
{
    // A flat patch (normal +z) and, to its right, a patch rising along t (normal (-1,0,1)/√2).
    auto right = [](int i, int j) { return Vec3{1 + j / 3.0, i / 3.0, j / 3.0}; };
    std::string text = header({}, {}, {0, 1, 0}, {0, 0, 1}, 1) + patch_text("A", unit_square, "~", "B") +
                       patch_text("B", right, "A", "~");
    SurfaceDef def = parse_surface_text(text, "seam.s", command('s', 1, 2, 2));
    const TriangleMesh& mesh = def.prototype.geometry.mesh;
    Vec3 expected = normalize(Vec3{0, 0, 1} + normalize(Vec3{-1, 0, 1}));
    int found = 0;
    for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
        if (std::abs(mesh.positions[i][0] - 1) < 1e-6) {  // on the seam x = 1
            expect_near(v3(mesh.normals[i]), expected, 1e-5);
            ++found;
        }
    }
    EXPECT_EQ(found, 6);  // 3 vertices along s on each side
    // Away from the seam the normals are the patches' own.
    std::size_t far = 0;
    ASSERT_NE(find_vertex(mesh, {2, 1.0 / 3.0 * 1.5, 1}, 0.2, &far), nullptr);
    expect_near(v3(mesh.normals[far]), normalize(Vec3{-1, 0, 1}), 1e-5);
}

TEST(Surface, MismatchedNeighboursWarnAndKeepOwnNormals)
{
    set_warnings_enabled(false);
    auto right = [](int i, int j) { return Vec3{1 + j / 3.0, i / 3.0, j / 3.0}; };
    std::string text = header({}, {}, {0, 1, 0}, {0, 0, 1}, 1) + patch_text("A", unit_square, "~", "B") +
                       patch_text("B", right, "~", "~");
    SurfaceDef def = parse_surface_text(text, "seam.s", command('s', 1, 2, 2));
    set_warnings_enabled(true);
    const TriangleMesh& mesh = def.prototype.geometry.mesh;
    expect_near(v3(mesh.normals[2]), {0, 0, 1}, 1e-6);  // A's vertex s = 0, t = 1 on the seam
}

/// The one surface a view-file line defines.
SurfaceCommand view_surface(const std::string& line)
{
    return parse_view_file(line + "\n", "p.v").surfaces.at(0);
}

TEST(Surface, CommandParsing)
{
    SurfaceCommand c = view_surface("surface: l leaf.s 1.5 8 4");
    EXPECT_EQ(c.letter, 'l');
    EXPECT_EQ(c.file, "leaf.s");
    EXPECT_DOUBLE_EQ(c.scale, 1.5);
    EXPECT_EQ(c.s_steps, 8);
    EXPECT_EQ(c.t_steps, 4);
    EXPECT_FALSE(c.texture.has_value());
    c = view_surface("surface: l leaf.s 1 3");
    ASSERT_TRUE(c.texture.has_value());
    EXPECT_EQ(*c.texture, 2);  // tex 3 is Scene::textures[2]
    c = view_surface("surface: l leaf.s 1 2 2 0");
    EXPECT_EQ(*c.texture, no_texture);
    c = view_surface("tsurface: t tri.ray 2");
    EXPECT_EQ(c.kind, SurfaceCommand::Kind::triangles);
    EXPECT_THROW(view_surface("surface: lx leaf.s 1"), Error);
    EXPECT_THROW(view_surface("surface: l leaf.s"), Error);
}

TEST(Surface, LineCommandDefinesASurface)
{
    // `line: id file size [s t [tex]]` is read as `surface:` (cpfg's read_surface) but a
    // lone number after the size is not a texture there.
    SurfaceCommand c = view_surface("line: L line.s .01");
    EXPECT_EQ(c.kind, SurfaceCommand::Kind::bicubic);
    EXPECT_EQ(c.letter, 'L');
    EXPECT_EQ(c.file, "line.s");
    EXPECT_DOUBLE_EQ(c.scale, 0.01);
    set_warnings_enabled(false);
    c = view_surface("line: L line.s 1 3");
    set_warnings_enabled(true);
    EXPECT_FALSE(c.texture.has_value());
    EXPECT_EQ(c.s_steps, 0);
    c = view_surface("line: L line.s 1 2 4 3");
    EXPECT_EQ(c.s_steps, 2);
    EXPECT_EQ(c.t_steps, 4);
    ASSERT_TRUE(c.texture.has_value());
    EXPECT_EQ(*c.texture, 2);
}

TEST(SurfaceConformance, SedgeLineSurfaceIsLoaded)
{
    std::filesystem::path view = corpus() / "cpfg/10-manuals/11-CPFG/Sedge/female.v";
    if (!std::filesystem::exists(view))
        GTEST_SKIP() << "corpus not found";
    set_warnings_enabled(false);  // the view names a missing bract.s
    std::vector<SurfaceDef> defs = load_view_surfaces(read_view_file(view));
    set_warnings_enabled(true);
    auto line = std::find_if(defs.begin(), defs.end(), [](const SurfaceDef& d) { return d.letter == 'L'; });
    ASSERT_NE(line, defs.end());
    // line.s: two patches of a tube 2000 long along its heading, at size 2000 and scale
    // 0.01, so 0.01 long: every vertex has 0 <= y <= 0.01.
    const TriangleMesh& mesh = line->prototype.geometry.mesh;
    ASSERT_GT(mesh.positions.size(), 0u);
    float lo = mesh.positions[0][1], hi = lo;
    for (const Float3& p : mesh.positions) {
        lo = std::min(lo, p[1]);
        hi = std::max(hi, p[1]);
    }
    EXPECT_NEAR(lo, 0, 1e-6);
    EXPECT_NEAR(hi, 0.01, 1e-6);
}

TEST(Surface, ScaleParameters)
{
    std::vector<float> none, one{2}, two{2, 5}, three{2, 3, 4};
    expect_near(surface_scale(none, 0.5), {0.5, 0.5, 0.5}, 0);
    expect_near(surface_scale(one, 1), {2, 2, 2}, 0);
    expect_near(surface_scale(two, 1), {2, 2, 2}, 0);
    expect_near(surface_scale(three, 2), {4, 6, 8}, 0);
}

TEST(Surface, ErrorsNameLineAndColumn)
{
    std::string text = header({}, {}, {0, 1, 0}, {0, 0, 1}, 1) + "p\nTOP COLOUR: 0\n";
    try {
        parse_surface_text(text, "bad.s", command('b', 1));
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_EQ(e.loc().file, "bad.s");
        EXPECT_EQ(e.loc().line, 8);
        EXPECT_EQ(e.loc().column, 5);
    }
    EXPECT_THROW(parse_surface_text(header({}, {}, {0, 1, 0}, {0, 0, 1}, 0) + patch_text("p", unit_square),
                                    "z.s", command('z', 1)),
                 Error);
}

TEST(Surface, TruncatedFilesThrowErrorsOnly)
{
    set_warnings_enabled(false);
    std::string text = header({0.5, 0, 0}, {0.5, 1, 0}, {0, 1, 0}, {0, 0, 1}, 2) +
                       patch_text("A", unit_square, "~", "B") +
                       patch_text("B", [](int i, int j) { return Vec3{1 + j / 3.0, i / 3.0, 0}; }, "A", "~");
    int parsed = 0;
    for (std::size_t n = 0;; n = std::min(n + 3, text.size())) {
        try {
            SurfaceDef d = parse_surface_text(text.substr(0, n), "t.s", command('t', 1, 2, 2));
            EXPECT_GT(d.prototype.geometry.mesh.size(), 0u);
            ++parsed;
        } catch (const Error&) {
        }
        if (n == text.size())
            break;
    }
    EXPECT_GT(parsed, 0);
    set_warnings_enabled(true);
}

TEST(Tsurface, ManualExample)
{
    std::string text =
        "name whatever\n"
        "triangle\n-0.5 1 0 0 0 1 0.5 0\n0 2 0 0 0 1 1 0.5\n0.5 1 0 0 0 1 0.5 1\n"
        "triangle\n0.5 1 0 0 0 1\n0 0 0, 0 0 1\n-0.5 1 0 0 0 0\n";
    SurfaceCommand c = command('t', 2);
    c.kind = SurfaceCommand::Kind::triangles;
    SurfaceDef def = parse_tsurface_text(text, "t.ray", c);
    const TriangleMesh& mesh = def.prototype.geometry.mesh;
    ASSERT_EQ(mesh.size(), 2u);
    expect_near(v3(mesh.positions[1]), {0, 4, 0}, 1e-6);  // scaled by 2
    EXPECT_FLOAT_EQ(mesh.uvs[1][0], 1);
    EXPECT_FLOAT_EQ(mesh.uvs[1][1], 0.5f);
    EXPECT_FLOAT_EQ(mesh.uvs[3][0], 0);  // no uv given
    expect_near(v3(mesh.normals[0]), {0, 0, 1}, 1e-6);
    // A zero normal becomes the face normal: (0.5,1)->(0,0)->(-0.5,1) turns clockwise: -z.
    expect_near(v3(mesh.normals[5]), {0, 0, -1}, 1e-6);
    EXPECT_FALSE(def.moves_turtle);
    EXPECT_EQ(mesh.material[1], inherit_material);
}

TEST(Tsurface, MalformedInput)
{
    SurfaceCommand c = command('t', 1);
    c.kind = SurfaceCommand::Kind::triangles;
    try {
        parse_tsurface_text("triangle\n0 0 0 0 0 1\n1 0 0 0 0 1\n", "u.ray", c);
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_EQ(e.loc().line, 1);
    }
    try {
        parse_tsurface_text("triangle\n0 0 0 0 0 1\n1 x 0 0 0 1\n", "u.ray", c);
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_EQ(e.loc().line, 3);
        EXPECT_EQ(e.loc().column, 3);
    }
    std::string text = "triangle\n-0.5 1 0 0 0 1 0.5 0\n0 2 0 0 0 1 1 0.5\n0.5 1 0 0 0 1 0.5 1\n";
    for (std::size_t n = 0; n <= text.size(); ++n) {
        try {
            parse_tsurface_text(text.substr(0, n), "u.ray", c);
        } catch (const Error&) {
        }
    }
}

// The original cpfg's rayshade output holds the tessellated surface `l` of LeafRandom
// (leaf.s, view "surface: l leaf.s 1 8 4") with per-surface texture coordinates.
TEST(SurfaceConformance, LeafRandomMatchesCpfgRayshadeObject)
{
    std::filesystem::path model = corpus() / "cpfg/10-manuals/15-VlabTools/LeafRandom";
    std::filesystem::path ray = corpus() / "oracle/10-manuals/15-VlabTools/LeafRandom/scene.ray";
    if (!std::filesystem::exists(ray) || !std::filesystem::exists(model / "leaf.s"))
        GTEST_SKIP() << "corpus not found";
    SurfaceCommand leaf = command('l', 1, 8, 4);
    leaf.file = "leaf.s";
    SurfaceDef def = read_surface(leaf, model);
    const TriangleMesh& mesh = def.prototype.geometry.mesh;
    EXPECT_EQ(mesh.size(), 64u);

    std::ifstream in(ray);
    std::string line;
    while (std::getline(in, line) && line != "name l grid 20 20 20") {
    }
    ASSERT_FALSE(in.eof()) << "object l not in scene.ray";
    int vertices = 0;
    while (std::getline(in, line) && line != "end") {
        if (line.rfind("triangle", 0) == 0)
            continue;
        std::istringstream v(line);
        Vec3 p, n;
        float u = 0, w = 0;
        v >> p.x >> p.y >> p.z >> n.x >> n.y >> n.z >> u >> w;
        std::size_t i = 0;
        ASSERT_NE(find_vertex(mesh, p, 2e-4, &i), nullptr) << line;
        // Rayshade output flips normals to the triangle's side: compare up to sign.
        EXPECT_NEAR(std::abs(dot(v3(mesh.normals[i]), n)), 1.0, 1e-4) << line;
        EXPECT_NEAR(def.uvs_per_surface[i][0], u, 2e-3) << line;
        EXPECT_NEAR(def.uvs_per_surface[i][1], w, 2e-3) << line;
        ++vertices;
    }
    EXPECT_EQ(vertices, 64 * 3);
}

// Every predefined surface of the oracle models that use them, against the triangles
// cpfg wrote to their rayshade output (positions, normals up to sign, texture
// coordinates per surface or per patch, triangle count).
TEST(SurfaceConformance, OracleSurfacesMatchCpfgRayshadeObjects)
{
    const std::pair<const char*, const char*> models[] = {
        {"10-manuals/15-VlabTools/LeafRandom", "leaf.v"},
        {"10-manuals/11-CPFG/Sedge", "sedge.v"},
        {"10-manuals/11-CPFG/TexturedSurfaces", "plant.v"},
        {"11-CPFG/02-Mod-vis-3D/11-sympodial-asym", "plant.v"},
        {"11-CPFG/02-Mod-vis-3D/06-comp-leaf-perspective", "leaf.v"},
        {"11-CPFG/02-Mod-vis-3D/08-leaf-pos", "leaf.v"},
        {"11-CPFG/02-Mod-vis-3D/09-monopodial-spiral", "plant.v"},
    };
    if (!std::filesystem::exists(corpus() / "oracle"))
        GTEST_SKIP() << "corpus not found";
    set_warnings_enabled(false);
    int objects = 0;
    for (const auto& [dir, view_name] : models) {
        SCOPED_TRACE(dir);
        std::vector<SurfaceDef> defs = load_view_surfaces(read_view_file(corpus() / "cpfg" / dir / view_name));
        std::ifstream in(corpus() / "oracle" / dir / "scene.ray");
        std::string line;
        const SurfaceDef* def = nullptr;
        int vertices = 0;
        bool per_surface = true, per_patch = true;
        while (std::getline(in, line)) {
            if (line.rfind("name ", 0) == 0 && line.find(" grid 20 20 20") != std::string::npos) {
                def = nullptr;
                for (const SurfaceDef& d : defs)
                    if (line == std::string("name ") + d.letter + " grid 20 20 20" ||
                        line == std::string("name ") + d.letter + "2 grid 20 20 20")
                        def = &d;
                ASSERT_NE(def, nullptr) << line;
                vertices = 0;
                per_surface = per_patch = true;
                continue;
            }
            if (!def)
                continue;
            if (line == "end") {
                EXPECT_EQ(static_cast<std::size_t>(vertices), 3 * def->prototype.geometry.mesh.size());
                EXPECT_TRUE(per_surface || per_patch) << "texture coordinates of " << def->letter;
                ++objects;
                def = nullptr;
                continue;
            }
            if (line.rfind("triangle", 0) == 0)
                continue;
            std::istringstream v(line);
            Vec3 p, n;
            v >> p.x >> p.y >> p.z >> n.x >> n.y >> n.z;
            const TriangleMesh& mesh = def->prototype.geometry.mesh;
            std::size_t i = 0;
            ASSERT_NE(find_vertex(mesh, p, 5e-4, &i), nullptr) << line;
            // Several vertices share a position at patch seams: any with this normal will do.
            bool normal_found = false;
            for (std::size_t k = 0; k < mesh.positions.size(); ++k)
                if (length(v3(mesh.positions[k]) - p) < 5e-4 &&
                    std::abs(std::abs(dot(v3(mesh.normals[k]), n)) - 1) < 2e-4)
                    normal_found = true;
            EXPECT_TRUE(normal_found) << line;
            float u = 0, w = 0;
            if (v >> u >> w) {
                bool surface_uv = false, patch_uv = false;
                for (std::size_t k = 0; k < mesh.positions.size(); ++k) {
                    if (length(v3(mesh.positions[k]) - p) >= 5e-4)
                        continue;
                    surface_uv |= std::abs(def->uvs_per_surface[k][0] - u) < 2e-3 &&
                                  std::abs(def->uvs_per_surface[k][1] - w) < 2e-3;
                    patch_uv |= std::abs(mesh.uvs[k][0] - u) < 2e-3 && std::abs(mesh.uvs[k][1] - w) < 2e-3;
                }
                per_surface &= surface_uv;
                per_patch &= patch_uv;
            }
            ++vertices;
        }
    }
    set_warnings_enabled(true);
    EXPECT_GE(objects, 9);
}

TEST(SurfaceConformance, EveryCorpusSurfaceFileReads)
{
    std::filesystem::path root = corpus() / "cpfg";
    if (!std::filesystem::exists(root))
        GTEST_SKIP() << "corpus not found";
    set_warnings_enabled(false);
    int files = 0;
    for (const auto& entry : std::filesystem::recursive_directory_iterator(root)) {
        if (entry.path().extension() != ".s")
            continue;
        SurfaceCommand c = command('x', 1);
        c.file = entry.path().filename();
        EXPECT_NO_THROW({
            SurfaceDef d = read_surface(c, entry.path().parent_path());
            EXPECT_GT(d.prototype.geometry.mesh.size(), 0u);
        }) << entry.path();
        ++files;
    }
    set_warnings_enabled(true);
    EXPECT_GE(files, 20);
}
