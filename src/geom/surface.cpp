// SPDX-License-Identifier: Apache-2.0
// Predefined bicubic surfaces (`.s` files) as prototypes, and their placement at the turtle.
#include "geom/surface.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <set>

#include "geom/patch.h"
#include "geom/text_input.h"
#include "geom/tsurface.h"

namespace cambium::geom {

// ---------------------------------------------------------------------------------------
// TextCursor

namespace detail {

TextCursor::TextCursor(std::string_view text, std::string file_name, int first_line,
                       int first_column)
    : m_text(text), m_file(std::move(file_name)), m_line(first_line), m_column(first_column)
{
}

void TextCursor::advance(std::size_t n)
{
    for (std::size_t i = 0; i < n && m_pos < m_text.size(); ++i, ++m_pos) {
        if (m_text[m_pos] == '\n') {
            ++m_line;
            m_column = 1;
        } else {
            ++m_column;
        }
    }
}

namespace {
bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v'; }
}  // namespace

void TextCursor::skip_blanks()
{
    while (m_pos < m_text.size() && is_blank(m_text[m_pos]))
        advance(1);
}

bool TextCursor::at_end()
{
    skip_blanks();
    return m_pos >= m_text.size();
}

bool TextCursor::at_line_end()
{
    while (m_pos < m_text.size() && m_text[m_pos] != '\n' && is_blank(m_text[m_pos]))
        advance(1);
    return m_pos >= m_text.size() || m_text[m_pos] == '\n';
}

bool TextCursor::try_literal(std::string_view literal)
{
    skip_blanks();
    if (m_text.substr(m_pos, literal.size()) != literal)
        return false;
    advance(literal.size());
    return true;
}

void TextCursor::expect(std::string_view literal, const char* context)
{
    if (!try_literal(literal))
        throw error("expected '" + std::string(literal) + "' " + context);
}

std::optional<double> TextCursor::try_number()
{
    skip_blanks();
    std::size_t start = m_pos;
    std::size_t p = start;
    if (p < m_text.size() && m_text[p] == '+')
        ++p;  // from_chars does not take a leading '+', strtod does
    double value = 0;
    auto [end, ec] = std::from_chars(m_text.data() + p, m_text.data() + m_text.size(), value);
    if (ec != std::errc() || !std::isfinite(value))
        return std::nullopt;
    advance(static_cast<std::size_t>(end - m_text.data()) - start);
    return value;
}

double TextCursor::number(const char* what)
{
    if (auto v = try_number())
        return *v;
    if (at_end())
        throw error(std::string("unexpected end of file: expected ") + what);
    throw error(std::string("expected a number: ") + what);
}

int TextCursor::integer(const char* what)
{
    FileLoc where = (skip_blanks(), loc());
    double v = number(what);
    if (v != std::floor(v) || std::fabs(v) > 1e9)
        throw Error(where, std::string("expected an integer: ") + what);
    return static_cast<int>(v);
}

std::string TextCursor::word(const char* what)
{
    if (at_end())
        throw error(std::string("unexpected end of file: expected ") + what);
    std::size_t start = m_pos;
    while (m_pos < m_text.size() && !is_blank(m_text[m_pos]))
        advance(1);
    return std::string(m_text.substr(start, m_pos - start));
}

std::string_view TextCursor::rest_of_line()
{
    std::size_t start = m_pos;
    while (m_pos < m_text.size() && m_text[m_pos] != '\n')
        advance(1);
    std::string_view line = m_text.substr(start, m_pos - start);
    if (m_pos < m_text.size())
        advance(1);
    return line;
}

FileLoc TextCursor::loc() const { return FileLoc{m_file, m_line, m_column}; }

}  // namespace detail

using detail::TextCursor;

// ---------------------------------------------------------------------------------------
// The view-file command

namespace {

/// The text with C comments blanked (columns kept), lines joined again.
std::string without_comments(std::string_view text)
{
    std::string out;
    out.reserve(text.size());
    for (const SourceLine& line : split_lines_without_comments(text)) {
        out += line.text;
        out += '\n';
    }
    return out;
}

}  // namespace

// ---------------------------------------------------------------------------------------
// The `.s` reader

namespace {

constexpr std::size_t max_surface_patches = 4096;

// Neighbour directions in the file's order: AL A AR L R BL B BR; direction 7 - n is the
// opposite one.
constexpr int neighbour_count = 8;
constexpr std::array<const char*, neighbour_count> neighbour_labels = {"AL:", "A:", "AR:", "L:",
                                                                       "R:",  "BL:", "B:", "BR:"};

struct FilePatch {
    std::string name;
    FileLoc loc;
    PatchColours colours;
    PatchControl control{};
    std::array<std::string, neighbour_count> neighbours;
};

struct Frame {
    Vec3 contact;
    Vec3 left, heading, up;
    double scale = 1;

    Vec3 apply(const Vec3& p) const
    {
        Vec3 d = (p - contact) * scale;
        // cpfg (patches.c) maps x to L, y to H, z to U.
        return left * d.x + heading * d.y + up * d.z;
    }
};

Vec3 read_labelled_point(TextCursor& in, const char* context)
{
    Vec3 v;
    in.expect("X:", context);
    v.x = in.number(context);
    in.expect("Y:", context);
    v.y = in.number(context);
    in.expect("Z:", context);
    v.z = in.number(context);
    return v;
}

int checked_steps(int steps, const FileLoc& loc, const char* which)
{
    if (steps < 1) {
        warn(loc, std::string(which) + " precision below 1: 1 used");
        return 1;
    }
    if (steps > max_patch_steps) {
        warn(loc, std::string(which) + " precision above " + std::to_string(max_patch_steps) +
                      ": " + std::to_string(max_patch_steps) + " used");
        return max_patch_steps;
    }
    return steps;
}

FilePatch read_patch(TextCursor& in, std::string name, FileLoc loc)
{
    FilePatch p;
    p.name = std::move(name);
    p.loc = std::move(loc);
    // The colours (used by colormap-mode lighting); the diffuse coefficients are read
    // and not used (docs/deviations.md).
    in.expect("TOP", "(patch colours)");
    in.expect("COLOR:", "(patch colours)");
    p.colours.top = in.integer("top colour");
    in.expect("DIFFUSE:", "(patch colours)");
    in.number("top diffuse");
    in.expect("BOTTOM", "(patch colours)");
    in.expect("COLOR:", "(patch colours)");
    p.colours.bottom = in.integer("bottom colour");
    in.expect("DIFFUSE:", "(patch colours)");
    in.number("bottom diffuse");
    for (int n = 0; n < neighbour_count; ++n) {
        in.expect(neighbour_labels[static_cast<std::size_t>(n)], "(patch neighbours)");
        p.neighbours[static_cast<std::size_t>(n)] = in.word("a neighbour patch name or '~'");
    }
    for (auto& point : p.control) {
        point.x = in.number("a control point coordinate");
        point.y = in.number("a control point coordinate");
        point.z = in.number("a control point coordinate");
    }
    return p;
}

// The vertex pairs (this patch, neighbour) shared along direction n.
std::vector<std::pair<std::array<int, 2>, std::array<int, 2>>> shared_vertices(int n, int S, int T)
{
    std::vector<std::pair<std::array<int, 2>, std::array<int, 2>>> v;
    switch (n) {
    case 0: v.push_back({{0, 0}, {S, T}}); break;
    case 1: for (int t = 0; t <= T; ++t) v.push_back({{0, t}, {S, t}}); break;
    case 2: v.push_back({{0, T}, {S, 0}}); break;
    case 3: for (int s = 0; s <= S; ++s) v.push_back({{s, 0}, {s, T}}); break;
    case 4: for (int s = 0; s <= S; ++s) v.push_back({{s, T}, {s, 0}}); break;
    case 5: v.push_back({{S, 0}, {0, T}}); break;
    case 6: for (int t = 0; t <= T; ++t) v.push_back({{S, t}, {0, t}}); break;
    default: v.push_back({{S, T}, {0, 0}}); break;
    }
    return v;
}

struct Link {
    int index = -1;  ///< the neighbour patch, -1: none
    bool averaged = false;
};

/// Resolves neighbour names; nullopt (with a warning) when they do not match, in which
/// case cpfg rejects the surface and Cambium draws it without smoothing its seams.
std::optional<std::vector<std::array<Link, neighbour_count>>> resolve_links(
    const std::vector<FilePatch>& patches)
{
    std::vector<std::array<Link, neighbour_count>> links(patches.size());
    bool ok = true;
    for (std::size_t p = 0; p < patches.size(); ++p) {
        for (int n = 0; n < neighbour_count; ++n) {
            const std::string& name = patches[p].neighbours[static_cast<std::size_t>(n)];
            if (name == "~")
                continue;
            auto it = std::find_if(patches.begin(), patches.end(),
                                   [&](const FilePatch& q) { return q.name == name; });
            if (it == patches.end()) {
                warn(patches[p].loc, "no patch '" + name + "' (neighbour of '" + patches[p].name + "')");
                ok = false;
                continue;
            }
            if (it->neighbours[static_cast<std::size_t>(7 - n)] != patches[p].name) {
                warn(patches[p].loc, "patch '" + patches[p].name + "' and its neighbour '" + name +
                                         "' do not name each other");
                ok = false;
                continue;
            }
            links[p][static_cast<std::size_t>(n)].index = static_cast<int>(it - patches.begin());
        }
    }
    if (!ok)
        return std::nullopt;
    return links;
}

/// cpfg's calculate_neighbouring_vertex_normals: per patch, add the neighbours' normals
/// along every not yet averaged seam, then normalise and copy the result to the neighbour.
void average_seam_normals(std::vector<PatchGrid>& grids,
                          std::vector<std::array<Link, neighbour_count>>& links)
{
    if (grids.empty())
        return;
    const int S = grids[0].s_steps, T = grids[0].t_steps;
    for (std::size_t p = 0; p < grids.size(); ++p) {
        for (int pass = 0; pass < 2; ++pass) {
            for (int n = 0; n < neighbour_count; ++n) {
                Link& link = links[p][static_cast<std::size_t>(n)];
                if (link.index < 0 || link.averaged)
                    continue;
                PatchGrid& q = grids[static_cast<std::size_t>(link.index)];
                for (const auto& [a, b] : shared_vertices(n, S, T)) {
                    Vec3& mine = grids[p].normals[grids[p].index(a[0], a[1])];
                    Vec3& theirs = q.normals[q.index(b[0], b[1])];
                    if (pass == 0) {
                        mine += theirs;
                    } else {
                        mine = normalize(mine);
                        theirs = mine;
                    }
                }
            }
            if (pass == 1) {
                for (int n = 0; n < neighbour_count; ++n) {
                    Link& link = links[p][static_cast<std::size_t>(n)];
                    if (link.index >= 0 && !link.averaged)
                        links[static_cast<std::size_t>(link.index)][static_cast<std::size_t>(7 - n)]
                            .averaged = true;
                }
            }
        }
    }
}

std::vector<Float2> per_surface_uvs(const TriangleMesh& mesh)
{
    float lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (const Float3& p : mesh.positions)
        for (int k = 0; k < 2; ++k) {
            lo[k] = std::min(lo[k], p[static_cast<std::size_t>(k)]);
            hi[k] = std::max(hi[k], p[static_cast<std::size_t>(k)]);
        }
    std::vector<Float2> uvs;
    uvs.reserve(mesh.positions.size());
    for (const Float3& p : mesh.positions) {
        Float2 uv{};
        for (int k = 0; k < 2; ++k) {
            float extent = hi[k] - lo[k];
            uv[static_cast<std::size_t>(k)] = extent > 0 ? (p[static_cast<std::size_t>(k)] - lo[k]) / extent : 0.0f;
        }
        uvs.push_back(uv);
    }
    return uvs;
}

}  // namespace

SurfaceDef parse_surface_text(std::string_view text, const std::string& file_name,
                              const SurfaceCommand& command)
{
    SurfaceDef def;
    def.letter = command.letter;
    def.name = command.file.stem().string();
    def.kind = SurfaceCommand::Kind::bicubic;
    def.scale = command.scale;
    def.texture = command.texture;
    def.prototype.name = std::string(1, command.letter);

    std::string clean = without_comments(text);
    TextCursor in(clean, file_name);
    for (int i = 0; i < 6; ++i)
        in.number("the surface's bounds (xmin xmax ymin ymax zmin zmax)");

    int file_steps = default_patch_steps;
    FileLoc precision_loc = in.loc();
    if (in.try_literal("PRECISION")) {
        in.expect("S:", "(PRECISION)");
        file_steps = in.integer("S precision");
        in.expect("T:", "(PRECISION)");
        in.integer("T precision");  // cpfg takes both precisions from S (patches.c)
    }
    def.s_steps = checked_steps(command.s_steps != 0 ? command.s_steps : file_steps,
                                precision_loc, "S");
    def.t_steps = checked_steps(command.t_steps != 0 ? command.t_steps : file_steps,
                                precision_loc, "T");

    in.expect("CONTACT", "(the surface header)");
    in.expect("POINT", "(the surface header)");
    def.contact_point = read_labelled_point(in, "(CONTACT POINT)");
    in.expect("END", "(the surface header)");
    in.expect("POINT", "(the surface header)");
    def.end_point = read_labelled_point(in, "(END POINT)");
    in.expect("HEADING", "(the surface header)");
    def.heading = read_labelled_point(in, "(HEADING)");
    in.expect("UP", "(the surface header)");
    def.up = read_labelled_point(in, "(UP)");
    in.expect("SIZE:", "(the surface header)");
    FileLoc size_loc = in.loc();
    def.size = in.number("SIZE");
    if (def.size == 0)
        throw Error(size_loc, "SIZE must not be 0");

    Frame frame;
    frame.contact = def.contact_point;
    frame.heading = normalize(def.heading);
    Vec3 up = normalize(def.up);
    // As cpfg: L = H x U, then U = L x H, neither normalised again.
    frame.left = cross(frame.heading, up);
    frame.up = cross(frame.left, frame.heading);
    frame.scale = command.scale / def.size;
    def.local_end_point = frame.apply(def.end_point);

    std::vector<FilePatch> patches;
    while (!in.at_end()) {
        FileLoc loc = in.loc();
        std::string name = in.word("a patch name");
        if (in.at_end()) {
            warn(loc, "patch '" + name + "' without data at the end of the file ignored");
            break;
        }
        if (patches.size() >= max_surface_patches)
            throw Error(loc, "too many patches (the limit is " + std::to_string(max_surface_patches) + ")");
        patches.push_back(read_patch(in, std::move(name), loc));
        for (Vec3& p : patches.back().control) {
            p = frame.apply(p);
            def.hull_points.push_back(p);
        }
    }
    if (patches.empty())
        throw in.error("surface without patches");

    std::vector<PatchGrid> grids;
    grids.reserve(patches.size());
    for (const FilePatch& p : patches)
        grids.push_back(sample_patch(PatchBasis::bezier, p.control, def.s_steps, def.t_steps));
    if (auto links = resolve_links(patches))
        average_seam_normals(grids, *links);

    std::int16_t texture = def.texture.value_or(no_texture);
    TriangleMesh& mesh = def.prototype.geometry.mesh;
    bool coloured = false;
    for (std::size_t i = 0; i < grids.size(); ++i) {
        append_patch_grid(grids[i], inherit_material, inherit_material, texture, mesh);
        const PatchColours& c = patches[i].colours;
        def.patch_colours.resize(mesh.triangles.size(), c);
        coloured = coloured || c.top != 0 || c.bottom != 0;
    }
    if (!coloured)
        def.patch_colours.clear();
    def.uvs_per_surface = per_surface_uvs(mesh);
    return def;
}

SurfaceDef read_surface(const SurfaceCommand& command, const std::filesystem::path& base_dir)
{
    std::filesystem::path file = command.file.is_absolute() ? command.file : base_dir / command.file;
    std::string text = read_text_file(file, command.kind == SurfaceCommand::Kind::bicubic
                                                ? "surface file"
                                                : "tsurface file");
    if (command.kind == SurfaceCommand::Kind::triangles) {
        SurfaceDef def = parse_tsurface_text(text, file.string(), command);
        for (const Float3& p : def.prototype.geometry.mesh.positions)
            def.hull_points.push_back(Vec3{p[0], p[1], p[2]});  // cpfg: every triangle vertex
        return def;
    }
    return parse_surface_text(text, file.string(), command);
}

std::vector<SurfaceDef> load_view_surfaces(const ViewFile& view)
{
    std::vector<SurfaceDef> defs;
    std::set<char> letters;
    const std::filesystem::path base_dir = view.path.parent_path();
    for (const SurfaceCommand& sc : view.surfaces) {
        if (letters.count(sc.letter)) {
            warn(sc.loc, std::string("surface '") + sc.letter + "' defined twice; ignored");
            continue;
        }
        std::filesystem::path file = sc.file.is_absolute() ? sc.file : base_dir / sc.file;
        std::error_code ec;
        if (!std::filesystem::is_regular_file(file, ec)) {
            warn(sc.loc, "cannot open surface file " + file.string() + "; surface '" +
                                  std::string(1, sc.letter) + "' ignored");
            continue;
        }
        defs.push_back(read_surface(sc, base_dir));
        letters.insert(sc.letter);
    }
    return defs;
}

// ---------------------------------------------------------------------------------------
// Placement

Vec3 surface_scale(std::span<const float> parameters, double turtle_scale)
{
    Vec3 s{1, 1, 1};
    if (parameters.size() >= 3)
        s = {parameters[0], parameters[1], parameters[2]};
    else if (!parameters.empty())
        s = {parameters[0], parameters[0], parameters[0]};
    return s * turtle_scale;
}

std::array<float, 12> surface_instance_transform(const SurfaceDef&, const Vec3& position,
                                                 const Vec3& heading, const Vec3& left,
                                                 const Vec3& up, const Vec3& scale)
{
    const Vec3 columns[4] = {left * scale.x, heading * scale.y, up * scale.z, position};
    std::array<float, 12> m{};
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 3; ++r)
            m[static_cast<std::size_t>(3 * c + r)] = static_cast<float>(columns[c][r]);
    return m;
}

Vec3 surface_end_position(const SurfaceDef& def, const Vec3& position, const Vec3& heading,
                          const Vec3& left, const Vec3& up, double scale_x)
{
    if (!def.moves_turtle)
        return position;
    const Vec3& e = def.local_end_point;
    return position + (left * e.x + heading * e.y + up * e.z) * scale_x;
}

}  // namespace cambium::geom
