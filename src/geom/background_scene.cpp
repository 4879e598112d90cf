// SPDX-License-Identifier: Apache-2.0
// The background scene: cpfg's OpenGL-like statements (background.c) into plain geometry.
#include "geom/background_scene.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "geom/surface.h"
#include "geom/text_input.h"
#include "lsys/preprocessor.h"

namespace cambium::geom {

using detail::TextCursor;

namespace {

constexpr std::array<std::string_view, 18> keywords = {
    "polygon", "polygonuv", "rectangle", "mesh",       "prism",     "box",
    "cone",    "cylinder",  "sphere",    "material",   "pushmatrix", "popmatrix",
    "translate", "rotate",  "scale",     "multmatrix", "loadidentity", "loadmatrix"};

bool is_keyword(std::string_view word)
{
    return std::find(keywords.begin(), keywords.end(), word) != keywords.end();
}

}  // namespace

std::vector<BackgroundStatement> parse_background_text(std::string_view text,
                                                       const std::string& file_name)
{
    std::string clean;
    for (const SourceLine& line : split_lines_without_comments(text)) {
        clean += line.text;
        clean += '\n';
    }
    std::vector<BackgroundStatement> statements;
    std::size_t numbers = 0;
    TextCursor in(clean, file_name);
    while (!in.at_end()) {
        FileLoc loc = in.loc();
        std::string word = in.word("a statement");
        if (word[0] == '#') {  // preprocessor leftovers: the rest of the line
            in.rest_of_line();
            continue;
        }
        bool known = is_keyword(word);
        if (!known)
            warn(loc, "unknown background-scene keyword '" + word + "' ignored");
        BackgroundStatement st{word, {}, loc};
        while (auto v = in.try_number()) {
            if (++numbers > max_background_numbers)
                throw Error(loc, "background scene too large (more than " +
                                     std::to_string(max_background_numbers) + " numbers)");
            st.numbers.push_back(*v);
        }
        if (!known)
            continue;
        if (statements.size() >= max_background_primitives)
            throw Error(loc, "background scene too large (more than " +
                                 std::to_string(max_background_primitives) + " statements)");
        statements.push_back(std::move(st));
    }
    return statements;
}

namespace {

/// A 4x4 matrix, column-major as OpenGL's.
struct Matrix {
    std::array<double, 16> m{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

    double at(int row, int col) const { return m[static_cast<std::size_t>(4 * col + row)]; }
    Matrix operator*(const Matrix& b) const
    {
        Matrix r;
        for (int row = 0; row < 4; ++row)
            for (int col = 0; col < 4; ++col) {
                double sum = 0;
                for (int k = 0; k < 4; ++k)
                    sum += at(row, k) * b.at(k, col);
                r.m[static_cast<std::size_t>(4 * col + row)] = sum;
            }
        return r;
    }
    Vec3 point(const Vec3& p) const
    {
        return {at(0, 0) * p.x + at(0, 1) * p.y + at(0, 2) * p.z + at(0, 3),
                at(1, 0) * p.x + at(1, 1) * p.y + at(1, 2) * p.z + at(1, 3),
                at(2, 0) * p.x + at(2, 1) * p.y + at(2, 2) * p.z + at(2, 3)};
    }
    Vec3 vector(const Vec3& v) const
    {
        return {at(0, 0) * v.x + at(0, 1) * v.y + at(0, 2) * v.z,
                at(1, 0) * v.x + at(1, 1) * v.y + at(1, 2) * v.z,
                at(2, 0) * v.x + at(2, 1) * v.y + at(2, 2) * v.z};
    }
};

Matrix from_columns(const std::vector<double>& a)
{
    Matrix r;
    std::copy_n(a.begin(), 16, r.m.begin());
    return r;
}

Matrix translation(double x, double y, double z)
{
    Matrix r;
    r.m[12] = x;
    r.m[13] = y;
    r.m[14] = z;
    return r;
}

Matrix scaling(double x, double y, double z)
{
    Matrix r;
    r.m[0] = x;
    r.m[5] = y;
    r.m[10] = z;
    return r;
}

// glRotate: `degrees` counter-clockwise about the axis.
Matrix rotation(double degrees, Vec3 axis)
{
    Matrix r;
    axis = normalize(axis);
    if (length(axis) == 0)
        return r;
    double a = degrees * std::numbers::pi / 180, c = std::cos(a), s = std::sin(a);
    double x = axis.x, y = axis.y, z = axis.z;
    const double rows[3][3] = {{x * x * (1 - c) + c, x * y * (1 - c) - z * s, x * z * (1 - c) + y * s},
                               {y * x * (1 - c) + z * s, y * y * (1 - c) + c, y * z * (1 - c) - x * s},
                               {z * x * (1 - c) - y * s, z * y * (1 - c) + x * s, z * z * (1 - c) + c}};
    for (int row = 0; row < 3; ++row)
        for (int col = 0; col < 3; ++col)
            r.m[static_cast<std::size_t>(4 * col + row)] = rows[row][col];
    return r;
}

Float3 f3(const Vec3& v) { return {static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z)}; }

class Builder {
public:
    Builder(const Material& initial) : m_initial(initial) {}

    void run(const BackgroundStatement& st);
    BackgroundScene take() { return std::move(m_scene); }

private:
    bool need(const BackgroundStatement& st, std::size_t count, const char* what);
    std::uint16_t material();
    void set_material(const std::vector<double>& n);
    void triangle(const Vec3 (&p)[3], const Vec3 (&n)[3]);
    void flat_triangle(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& normal);
    void polygon(const std::vector<double>& n);
    void polygon_with_normals(const std::vector<double>& n);
    void rectangle(const Vec3& p1, const Vec3& p2, const Vec3& p3, const Vec3& p4);
    void rectangle_statement(const std::vector<double>& n);
    void mesh(const std::vector<double>& n);
    void box(double a, double b, double c);
    void sphere(double r);
    void ellipsoid(double r);
    void cylinder(double r1, double r2, double h);

    Material m_initial;
    BackgroundScene m_scene;
    int m_current = -1;  ///< index into m_scene.materials, -1: the initial one, not added yet
    Matrix m_matrix;
    std::vector<Matrix> m_stack;
};

bool Builder::need(const BackgroundStatement& st, std::size_t count, const char* what)
{
    if (st.numbers.size() >= count)
        return true;
    warn(st.loc, "'" + st.keyword + "' needs " + what + "; ignored");
    return false;
}

std::uint16_t Builder::material()
{
    if (m_current < 0) {
        m_scene.materials.push_back(m_initial);
        m_current = static_cast<int>(m_scene.materials.size()) - 1;
    }
    return static_cast<std::uint16_t>(m_current);
}

void Builder::set_material(const std::vector<double>& n)
{
    Material m = m_current < 0 ? m_initial : m_scene.materials[static_cast<std::size_t>(m_current)];
    auto rgb = [&](std::size_t i) {
        return Rgb{static_cast<float>(n[i]), static_cast<float>(n[i + 1]), static_cast<float>(n[i + 2])};
    };
    if (n.size() >= 4)
        m.ambient = rgb(0);
    if (n.size() >= 8) {
        m.diffuse = rgb(4);
        m.transparency = std::clamp(1.0f - static_cast<float>(n[7]), 0.0f, 1.0f);
    }
    if (n.size() >= 12)
        m.specular = rgb(8);
    if (n.size() >= 16)
        m.emission = rgb(12);
    if (n.size() >= 17)
        m.shininess = std::clamp(static_cast<float>(n[16]), 0.0f, 128.0f);
    if (m_scene.materials.size() >= 0xfff0)
        throw Error("background scene: too many material statements");
    m_scene.materials.push_back(m);
    m_current = static_cast<int>(m_scene.materials.size()) - 1;
}

void Builder::triangle(const Vec3 (&p)[3], const Vec3 (&n)[3])
{
    TriangleMesh& mesh = m_scene.geometry.mesh;
    const auto base = static_cast<std::uint32_t>(mesh.positions.size());
    for (int k = 0; k < 3; ++k) {
        mesh.positions.push_back(f3(p[k]));
        mesh.normals.push_back(f3(normalize(n[k])));
        mesh.uvs.push_back({0, 0});
    }
    mesh.triangles.push_back({base, base + 1, base + 2});
    std::uint16_t mat = material();
    mesh.material.push_back(mat);
    mesh.back_material.push_back(mat);
    mesh.texture.push_back(no_texture);
}

void Builder::flat_triangle(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& normal)
{
    triangle({m_matrix.point(a), m_matrix.point(b), m_matrix.point(c)}, {normal, normal, normal});
}

// A convex polygon as a fan from its first vertex; one normal for all, from the first
// three vertices, counter-clockwise (the side cpfg's rayshade output calls front).
void Builder::polygon(const std::vector<double>& n)
{
    auto vertex = [&](std::size_t i) { return Vec3{n[3 * i], n[3 * i + 1], n[3 * i + 2]}; };
    const std::size_t count = n.size() / 3;
    Vec3 normal = m_matrix.vector(cross(vertex(1) - vertex(0), vertex(2) - vertex(0)));
    for (std::size_t i = 2; i < count; ++i)
        flat_triangle(vertex(0), vertex(i - 1), vertex(i), normal);
}

void Builder::polygon_with_normals(const std::vector<double>& n)
{
    auto vertex = [&](std::size_t i) { return m_matrix.point({n[6 * i], n[6 * i + 1], n[6 * i + 2]}); };
    auto normal = [&](std::size_t i) {
        return m_matrix.vector({n[6 * i + 3], n[6 * i + 4], n[6 * i + 5]});
    };
    const std::size_t count = n.size() / 6;
    for (std::size_t i = 2; i < count; ++i)
        triangle({vertex(0), vertex(i - 1), vertex(i)}, {normal(0), normal(i - 1), normal(i)});
}

// cpfg's DrawRectangle: triangles p1 p2 p3 and p1 p3 p4 with one normal.
void Builder::rectangle(const Vec3& p1, const Vec3& p2, const Vec3& p3, const Vec3& p4)
{
    Vec3 normal = m_matrix.vector(cross(p2 - p1, p3 - p1));
    flat_triangle(p1, p2, p3, normal);
    flat_triangle(p1, p3, p4, normal);
}

void Builder::rectangle_statement(const std::vector<double>& n)
{
    double x0 = 0, y0 = 0;
    if (n.size() >= 4) {
        x0 = n[2];
        y0 = n[3];
    }
    int saved = m_current;
    if (n.size() >= 5) {  // cpfg scales the emission for this rectangle only
        Material m = m_scene.materials[material()];
        m.emission = {m.emission.r * static_cast<float>(n[4]), m.emission.g * static_cast<float>(n[4]),
                      m.emission.b * static_cast<float>(n[4])};
        m_scene.materials.push_back(m);
        m_current = static_cast<int>(m_scene.materials.size()) - 1;
    }
    rectangle({x0, y0, 0}, {x0 + n[0], y0, 0}, {x0 + n[0], y0 + n[1], 0}, {x0, y0 + n[1], 0});
    if (n.size() >= 5)
        m_current = saved;
}

// Vertices 2k, 2k+2, 2k+3, 2k+1 make the rectangle k (cpfg's order).
void Builder::mesh(const std::vector<double>& n)
{
    auto vertex = [&](std::size_t i) { return Vec3{n[3 * i], n[3 * i + 1], n[3 * i + 2]}; };
    const std::size_t count = n.size() / 3;
    for (std::size_t k = 0; 2 * k + 3 < count; ++k)
        rectangle(vertex(2 * k), vertex(2 * k + 2), vertex(2 * k + 3), vertex(2 * k + 1));
}

void Builder::box(double a, double b, double c)
{
    auto P = [&](int x, int y, int z) { return Vec3{x * a, y * b, z * c}; };
    rectangle(P(0, 0, 0), P(0, 0, 1), P(0, 1, 1), P(0, 1, 0));
    rectangle(P(1, 0, 0), P(1, 1, 0), P(1, 1, 1), P(1, 0, 1));
    rectangle(P(0, 0, 0), P(0, 1, 0), P(1, 1, 0), P(1, 0, 0));
    rectangle(P(0, 0, 1), P(1, 0, 1), P(1, 1, 1), P(0, 1, 1));
    // cpfg's order; these two faces are wound inward (harmless: one material for both sides).
    rectangle(P(0, 0, 0), P(0, 0, 1), P(1, 0, 1), P(1, 0, 0));
    rectangle(P(0, 1, 0), P(1, 1, 0), P(1, 1, 1), P(0, 1, 1));
}

// cpfg's window draws the sphere under the current matrix (manual 5.4.10: a sphere under
// `scale 1 0.7 0.7` is an ellipsoid; only its rayshade output writes a plain sphere).
// A matrix that keeps shapes (rotation and uniform scale) gives a sphere primitive,
// any other an ellipsoid of triangles.
void Builder::sphere(double r)
{
    Vec3 c = m_matrix.point({0, 0, 0});
    Vec3 a = m_matrix.vector({1, 0, 0}), b = m_matrix.vector({0, 1, 0}), z = m_matrix.vector({0, 0, 1});
    double s = length(a);
    double tolerance = 1e-9 * std::max(s, 1.0);
    bool keeps_shape = std::fabs(length(b) - s) <= tolerance && std::fabs(length(z) - s) <= tolerance &&
                       std::fabs(dot(a, b)) <= tolerance * s && std::fabs(dot(b, z)) <= tolerance * s &&
                       std::fabs(dot(a, z)) <= tolerance * s;
    if (!keeps_shape) {
        ellipsoid(r);
        return;
    }
    Spheres& spheres = m_scene.geometry.spheres;
    spheres.centres.push_back({static_cast<float>(c.x), static_cast<float>(c.y), static_cast<float>(c.z),
                               static_cast<float>(r * s)});
    spheres.material.push_back(material());
    spheres.texture.push_back(no_texture);
}

// The sphere of radius r as latitude-longitude triangles through the current matrix;
// normals by the inverse transpose (columns b x c, c x a, a x b of the linear part).
void Builder::ellipsoid(double r)
{
    constexpr int slices = 32, stacks = 16;
    Vec3 a = m_matrix.vector({1, 0, 0}), b = m_matrix.vector({0, 1, 0}), c = m_matrix.vector({0, 0, 1});
    Vec3 na = cross(b, c), nb = cross(c, a), nc = cross(a, b);
    if (dot(a, na) < 0) {  // a mirroring matrix: keep normals outward
        na = na * -1.0;
        nb = nb * -1.0;
        nc = nc * -1.0;
    }
    auto unit = [](int i, int j) {
        double theta = std::numbers::pi * j / stacks, phi = 2 * std::numbers::pi * i / slices;
        return Vec3{std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi)};
    };
    auto point = [&](const Vec3& u) { return m_matrix.point(u * r); };
    auto normal = [&](const Vec3& u) { return na * u.x + nb * u.y + nc * u.z; };
    for (int j = 0; j < stacks; ++j)
        for (int i = 0; i < slices; ++i) {
            Vec3 u00 = unit(i, j), u10 = unit(i + 1, j), u01 = unit(i, j + 1), u11 = unit(i + 1, j + 1);
            if (j > 0)
                triangle({point(u00), point(u10), point(u11)}, {normal(u00), normal(u10), normal(u11)});
            if (j < stacks - 1)
                triangle({point(u00), point(u11), point(u01)}, {normal(u00), normal(u11), normal(u01)});
        }
}

// A turtle segment from the transformed origin to the transformed (0, h, 0) with radii
// r1, r2 (unscaled, as cpfg's line width), closed by a disc at each end.
void Builder::cylinder(double r1, double r2, double h)
{
    Vec3 a = m_matrix.point({0, 0, 0});
    Vec3 b = m_matrix.point({0, h, 0});
    Vec3 axis = normalize(b - a);
    std::uint16_t mat = material();
    LinearCurves& lines = m_scene.geometry.lines;
    const auto first = static_cast<std::uint32_t>(lines.keys.size());
    lines.keys.push_back({static_cast<float>(a.x), static_cast<float>(a.y), static_cast<float>(a.z),
                          static_cast<float>(r1)});
    lines.keys.push_back({static_cast<float>(b.x), static_cast<float>(b.y), static_cast<float>(b.z),
                          static_cast<float>(r2)});
    lines.v.push_back(0);
    lines.v.push_back(0);
    lines.segments.push_back(first);
    lines.flags.push_back(0);
    lines.material.push_back(mat);
    lines.texture.push_back(no_texture);
    Discs& discs = m_scene.geometry.discs;
    const Vec3 ends[2] = {a, b};
    const double radii[2] = {r1, r2};
    const Vec3 normals[2] = {-axis, axis};
    for (int k = 0; k < 2; ++k) {
        if (radii[k] <= 0)
            continue;
        discs.centres.push_back({static_cast<float>(ends[k].x), static_cast<float>(ends[k].y),
                                 static_cast<float>(ends[k].z), static_cast<float>(radii[k])});
        discs.normals.push_back(f3(normals[k]));
        discs.material.push_back(mat);
        discs.back_material.push_back(mat);
    }
}

void Builder::run(const BackgroundStatement& st)
{
    const std::string& k = st.keyword;
    const std::vector<double>& n = st.numbers;
    if (k == "material") {
        set_material(n);
    } else if (k == "polygon") {
        if (need(st, 9, "at least three points"))
            polygon(n);
    } else if (k == "polygonuv") {
        if (need(st, 18, "at least three points with normals"))
            polygon_with_normals(n);
    } else if (k == "rectangle") {
        if (need(st, 2, "two values"))
            rectangle_statement(n);
    } else if (k == "mesh") {
        if (need(st, 12, "at least four points"))
            mesh(n);
    } else if (k == "box" || k == "prism") {
        if (need(st, 3, "three values"))
            box(n[0], n[1], n[2]);
    } else if (k == "sphere") {
        if (need(st, 1, "a radius"))
            sphere(n[0]);
    } else if (k == "cylinder") {
        if (need(st, 2, "a radius and a height"))
            cylinder(n[0], n[0], n[1]);
    } else if (k == "cone") {
        if (need(st, 3, "two radii and a height"))
            cylinder(n[0], n[1], n[2]);
    } else if (k == "pushmatrix") {
        if (m_stack.size() >= max_background_matrix_depth)
            throw Error(st.loc, "pushmatrix: the matrix stack is deeper than " +
                                    std::to_string(max_background_matrix_depth));
        m_stack.push_back(m_matrix);
    } else if (k == "popmatrix") {
        if (m_stack.empty()) {
            warn(st.loc, "popmatrix without pushmatrix ignored");
        } else {
            m_matrix = m_stack.back();
            m_stack.pop_back();
        }
    } else if (k == "loadidentity") {
        m_matrix = Matrix{};
    } else if (k == "loadmatrix") {
        if (need(st, 16, "16 values"))
            m_matrix = from_columns(n);
    } else if (k == "multmatrix") {
        if (need(st, 16, "16 values"))
            m_matrix = m_matrix * from_columns(n);
    } else if (k == "translate") {
        if (need(st, 3, "three values"))
            m_matrix = m_matrix * translation(n[0], n[1], n[2]);
    } else if (k == "rotate") {
        if (need(st, 4, "an angle and an axis"))
            m_matrix = m_matrix * rotation(n[0], {n[1], n[2], n[3]});
    } else if (k == "scale") {
        if (need(st, 3, "three values"))
            m_matrix = m_matrix * scaling(n[0], n[1], n[2]);
    }
}

}  // namespace

BackgroundScene build_background_scene(const std::vector<BackgroundStatement>& statements,
                                       const Material& initial_material)
{
    Builder builder(initial_material);
    for (const BackgroundStatement& st : statements)
        builder.run(st);
    return builder.take();
}

namespace {
// Whether some line starts with '#' (after blanks): only then is cpp worth running.
bool has_directive(std::string_view text)
{
    std::size_t pos = 0;
    while (pos < text.size()) {
        std::size_t first = text.find_first_not_of(" \t", pos);
        if (first != std::string_view::npos && text[first] == '#')
            return true;
        std::size_t end = text.find('\n', pos);
        if (end == std::string_view::npos)
            break;
        pos = end + 1;
    }
    return false;
}
}  // namespace

BackgroundScene read_background_scene(std::span<const std::filesystem::path> files,
                                      const std::filesystem::path& base_dir,
                                      const Material& initial_material, const FileLoc& loc,
                                      const std::optional<std::filesystem::path>& confine_to)
{
    std::vector<BackgroundStatement> statements;
    for (const std::filesystem::path& named : files) {
        const std::filesystem::path file = named.is_relative() ? base_dir / named : named;
        std::error_code ec;
        if (!std::filesystem::is_regular_file(file, ec))
            throw Error(loc, "cannot read the background scene file " + file.string() +
                                 (std::filesystem::exists(file, ec) ? ": not a regular file"
                                                                    : ": no such file"));
        std::string text = read_text_file(file, "background scene file");
        if (has_directive(text)) {  // cpfg runs background files through cpp
            lsys::PreprocessOptions options;
            options.folder = file.parent_path();  // "" (the current folder) is fine here
            options.confine_to = confine_to;
            text = lsys::preprocess(text, file.string(), options);
        }
        std::vector<BackgroundStatement> more = parse_background_text(text, file.string());
        if (statements.size() + more.size() > max_background_primitives)
            throw Error(loc, "background scene too large");
        statements.insert(statements.end(), std::make_move_iterator(more.begin()),
                          std::make_move_iterator(more.end()));
    }
    return build_background_scene(statements, initial_material);
}

BackgroundScene load_view_background(const ViewFile& view, const Material& initial_material,
                                     const std::optional<std::filesystem::path>& confine_to)
{
    BackgroundScene scene;
    for (const BackgroundSceneFiles& c : view.background_scenes) {
        BackgroundScene more = read_background_scene(c.files, view.path.parent_path(), initial_material, c.loc,
                                                     confine_to);
        auto offset = static_cast<std::uint16_t>(scene.materials.size());
        offset_materials(more.geometry, offset);
        append_geometry(scene.geometry, more.geometry);
        scene.materials.insert(scene.materials.end(), more.materials.begin(), more.materials.end());
    }
    return scene;
}

namespace {

template <class T>
void fill_to(std::vector<T>& v, std::size_t size, T value)
{
    if (v.size() < size)
        v.resize(size, value);
}

template <class T>
void append(std::vector<T>& into, const std::vector<T>& from)
{
    into.insert(into.end(), from.begin(), from.end());
}

void shift(std::uint16_t& m, std::uint16_t offset)
{
    if (m != inherit_material)
        m = static_cast<std::uint16_t>(m + offset);
}

/// Appends curve segments: `keys` are the vertex arrays (LinearCurves::keys,
/// HermiteCurves::points) whose indices the segments hold; the tangents, if any, are
/// the caller's.
template <typename Curves>
void append_curves(Curves& a, const Curves& b, std::vector<Float4>& a_keys,
                   const std::vector<Float4>& b_keys)
{
    auto base = static_cast<std::uint32_t>(a_keys.size());
    fill_to(a.v, a_keys.size(), 0.0f);
    fill_to(a.texture, a.segments.size(), no_texture);
    append(a_keys, b_keys);
    append(a.v, b.v);
    fill_to(a.v, a_keys.size(), 0.0f);
    for (std::uint32_t s : b.segments)
        a.segments.push_back(s + base);
    append(a.flags, b.flags);
    append(a.material, b.material);
    append(a.texture, b.texture);
    fill_to(a.texture, a.segments.size(), no_texture);
}

}  // namespace

void cylinders_as_mesh(Geometry& geometry, int sides)
{
    LinearCurves& lines = geometry.lines;
    TriangleMesh& mesh = geometry.mesh;
    auto f3 = [](const Vec3& v) {
        return Float3{static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z)};
    };
    for (std::size_t s = 0; s < lines.segment_count(); ++s) {
        const Float4& ka = lines.keys[lines.segments[s]];
        const Float4& kb = lines.keys[lines.segments[s] + 1];
        const Vec3 a{ka[0], ka[1], ka[2]}, b{kb[0], kb[1], kb[2]};
        const double length = std::sqrt(dot(b - a, b - a));
        if (!(length > 0))
            continue;
        const Vec3 axis = (b - a) * (1 / length);
        // any two unit vectors perpendicular to the axis and to each other
        const Vec3 hint = std::abs(axis.x) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
        const Vec3 u = normalize(cross(axis, hint)), v = cross(axis, u);
        const auto first = static_cast<std::uint32_t>(mesh.positions.size());
        for (int i = 0; i < sides; ++i) {
            const double angle = 2 * std::numbers::pi * i / sides;
            const Vec3 radial = u * std::cos(angle) + v * std::sin(angle);
            // the frustum's outward normal leans toward the narrower end
            const Vec3 normal = normalize(radial * length + axis * (double(ka[3]) - kb[3]));
            mesh.positions.push_back(f3(a + radial * ka[3]));
            mesh.positions.push_back(f3(b + radial * kb[3]));
            mesh.normals.push_back(f3(normal));
            mesh.normals.push_back(f3(normal));
            mesh.uvs.push_back({0, 0});
            mesh.uvs.push_back({0, 0});
        }
        for (int i = 0; i < sides; ++i) {
            const std::uint32_t a0 = first + 2 * static_cast<std::uint32_t>(i), b0 = a0 + 1;
            const std::uint32_t a1 = first + 2 * static_cast<std::uint32_t>((i + 1) % sides), b1 = a1 + 1;
            for (const std::array<std::uint32_t, 3>& t : {std::array{a0, a1, b1}, std::array{a0, b1, b0}}) {
                mesh.triangles.push_back(t);
                mesh.material.push_back(lines.material[s]);
                mesh.back_material.push_back(lines.material[s]);
                mesh.texture.push_back(s < lines.texture.size() ? lines.texture[s] : no_texture);
            }
        }
    }
    lines = LinearCurves{};
}

/// Provenance entries of `a` (a_count primitives before the append) and `b`: kept when
/// either side has them, a primitive without one is no_module's.
void append_modules(std::vector<std::uint32_t>& a, std::size_t a_count,
                    const std::vector<std::uint32_t>& b, std::size_t b_count)
{
    if (a.empty() && b.empty())
        return;
    a.resize(a_count, no_module);
    if (b.size() == b_count)
        append(a, b);
    else
        a.resize(a_count + b_count, no_module);
}

namespace {

/// Provenance: `from`'s module records joined to `into`'s in string order (a module both
/// name keeps into's record).
void append_module_table(ModuleTable& into, const ModuleTable& from)
{
    if (from.records.empty())
        return;
    std::vector<std::uint16_t> name(from.names.size());
    for (std::size_t i = 0; i < from.names.size(); ++i) {
        auto at = std::find(into.names.begin(), into.names.end(), from.names[i]);
        name[i] = static_cast<std::uint16_t>(at - into.names.begin());
        if (at == into.names.end())
            into.names.push_back(from.names[i]);
    }
    std::vector<ModuleRecord> merged;
    merged.reserve(into.records.size() + from.records.size());
    // branch orders and births kept parallel where either table has them
    const bool orders = !into.orders.empty() || !from.orders.empty();
    const bool births = !into.births.empty() || !from.births.empty();
    std::vector<std::uint16_t> merged_orders;
    std::vector<std::uint32_t> merged_births;
    auto parallel = [&](const ModuleTable& t, std::size_t i) {
        if (orders)
            merged_orders.push_back(i < t.orders.size() ? t.orders[i] : ModuleTable::no_branch_order);
        if (births)
            merged_births.push_back(i < t.births.size() ? t.births[i] : t.records[i].index);
    };
    auto a = into.records.begin();
    auto keep_into = [&] {
        parallel(into, std::size_t(a - into.records.begin()));
        merged.push_back(*a++);
    };
    for (std::size_t f = 0; f < from.records.size(); ++f) {
        const ModuleRecord& r = from.records[f];
        while (a != into.records.end() && a->index < r.index)
            keep_into();
        if (a != into.records.end() && a->index == r.index)
            continue;
        parallel(from, f);
        merged.push_back({r.index, name[r.name], r.age});
    }
    while (a != into.records.end())
        keep_into();
    into.records = std::move(merged);
    into.orders = std::move(merged_orders);
    into.births = std::move(merged_births);
}

}  // namespace

void append_geometry(Geometry& into, const Geometry& from)
{
    append_module_table(into.modules, from.modules);
    append_modules(into.lines.module, into.lines.segment_count(), from.lines.module,
                   from.lines.segment_count());
    append_modules(into.curves.module, into.curves.segment_count(), from.curves.module,
                   from.curves.segment_count());
    append_modules(into.spheres.module, into.spheres.size(), from.spheres.module,
                   from.spheres.size());
    append_modules(into.discs.module, into.discs.size(), from.discs.module, from.discs.size());
    append_modules(into.mesh.module, into.mesh.size(), from.mesh.module, from.mesh.size());
    append_curves(into.lines, from.lines, into.lines.keys, from.lines.keys);
    append(into.curves.tangents, from.curves.tangents);
    {
        // end colours (generalized cylinders): kept when either side has them, a
        // segment without its own ends in its start colour
        HermiteCurves& a = into.curves;
        const HermiteCurves& b = from.curves;
        bool blended = !a.end_material.empty() || !b.end_material.empty();
        std::size_t a_segments = a.segments.size();
        append_curves(a, b, a.points, b.points);
        if (blended) {
            for (std::size_t i = a.end_material.size(); i < a_segments; ++i)
                a.end_material.push_back(a.material[i]);
            a.end_material.resize(a_segments);
            for (std::size_t i = 0; i < b.segments.size(); ++i)
                a.end_material.push_back(i < b.end_material.size() ? b.end_material[i]
                                                                    : b.material[i]);
        }
    }
    {
        Spheres& a = into.spheres;
        fill_to(a.texture, a.centres.size(), no_texture);
        append(a.centres, from.spheres.centres);
        append(a.material, from.spheres.material);
        append(a.texture, from.spheres.texture);
        fill_to(a.texture, a.centres.size(), no_texture);
    }
    {
        Discs& a = into.discs;
        append(a.centres, from.discs.centres);
        append(a.normals, from.discs.normals);
        append(a.material, from.discs.material);
        append(a.back_material, from.discs.back_material);
    }
    {
        TriangleMesh& a = into.mesh;
        const TriangleMesh& b = from.mesh;
        auto base = static_cast<std::uint32_t>(a.positions.size());
        append(a.positions, b.positions);
        append(a.normals, b.normals);
        if (!a.uvs.empty() || !b.uvs.empty()) {  // either may have dropped all-zero uvs
            fill_to(a.uvs, base, Float2{0, 0});
            append(a.uvs, b.uvs);
            fill_to(a.uvs, a.positions.size(), Float2{0, 0});
        }
        for (const auto& t : b.triangles)
            a.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
        append(a.material, b.material);
        append(a.back_material, b.back_material);
        fill_to(a.texture, a.triangles.size() - b.triangles.size(), no_texture);
        append(a.texture, b.texture);
        fill_to(a.texture, a.triangles.size(), no_texture);
    }
}

void offset_materials(Geometry& g, std::uint16_t offset)
{
    for (auto& m : g.lines.material) shift(m, offset);
    for (auto& m : g.curves.material) shift(m, offset);
    for (auto& m : g.curves.end_material) shift(m, offset);
    for (auto& m : g.spheres.material) shift(m, offset);
    for (auto& m : g.discs.material) shift(m, offset);
    for (auto& m : g.discs.back_material) shift(m, offset);
    for (auto& m : g.mesh.material) shift(m, offset);
    for (auto& m : g.mesh.back_material) shift(m, offset);
}

}  // namespace cambium::geom
