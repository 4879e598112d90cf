// SPDX-License-Identifier: Apache-2.0
// Interprets an L-system string with the turtle and builds the renderer-independent Scene.
#include "geom/interpreter.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <numbers>
#include <optional>
#include <sstream>
#include <string>
#include <unordered_map>
#include <vector>

#include "geom/patch.h"
#include "geom/polygon.h"
#include "geom/query.h"
#include "geom/scene_limits.h"
#include "geom/surface.h"
#include "geom/tropism.h"
#include "geom/turtle.h"

namespace cambium::geom {
namespace {

/// The turtle operation of every symbol of a table, looked up by name once.
std::vector<TurtleOp> symbol_ops(const lsys::SymbolTable& symbols)
{
    std::vector<TurtleOp> ops(symbols.size(), TurtleOp::None);
    auto bind = [&](const char* name, TurtleOp op) {
        int id = symbols.find(name);
        if (id >= 0)
            ops[static_cast<std::size_t>(id)] = op;
    };
#define X(op, name, doc) bind(name, TurtleOp::op);
#include "geom/turtle_symbols.def"
#undef X
    return ops;
}

/// Whether `format` is text around exactly one printf conversion of a double: flags,
/// width and precision of at most two digits each, conversion e E f F g G (an `l` may
/// precede it, as in cpfg's "%lg"). Anything else must not reach snprintf.
bool is_float_format(const std::string& format)
{
    std::size_t percent = format.find('%');
    if (percent == std::string::npos || format.find('%', percent + 1) != std::string::npos)
        return false;
    std::size_t i = format.find_first_not_of("-+ #0", percent + 1);
    auto digits = [&](std::size_t& at) {
        std::size_t start = at;
        while (at < format.size() && at - start < 3 && format[at] >= '0' && format[at] <= '9')
            ++at;
        return at - start <= 2;
    };
    if (i == std::string::npos || !digits(i))
        return false;
    if (i < format.size() && format[i] == '.' && !digits(++i))
        return false;
    if (i < format.size() && format[i] == 'l')
        ++i;
    return i < format.size() && std::string_view("eEfFgG").find(format[i]) != std::string_view::npos;
}

/// The sizes of every array of a Geometry, to cut it back to them.
struct GeometrySizes {
    explicit GeometrySizes(const Geometry& g)
        : line_keys(g.lines.keys.size()), line_v(g.lines.v.size()), line_segments(g.lines.segments.size()),
          curve_points(g.curves.points.size()), curve_v(g.curves.v.size()),
          curve_segments(g.curves.segments.size()), spheres(g.spheres.centres.size()),
          sphere_textures(g.spheres.texture.size()), discs(g.discs.centres.size()),
          positions(g.mesh.positions.size()), uvs(g.mesh.uvs.size()), triangles(g.mesh.triangles.size()),
          mesh_textures(g.mesh.texture.size())
    {
    }

    void truncate(Geometry& g) const
    {
        auto cut = [](auto& v, std::size_t n) {
            if (v.size() > n)
                v.resize(n);
        };
        LinearCurves& l = g.lines;
        cut(l.keys, line_keys), cut(l.v, line_v), cut(l.segments, line_segments), cut(l.flags, line_segments);
        cut(l.material, line_segments), cut(l.texture, line_segments);
        HermiteCurves& c = g.curves;
        cut(c.points, curve_points), cut(c.tangents, curve_points), cut(c.v, curve_v);
        cut(c.segments, curve_segments), cut(c.flags, curve_segments), cut(c.material, curve_segments);
        cut(c.texture, curve_segments), cut(c.end_material, curve_segments);
        cut(g.spheres.centres, spheres), cut(g.spheres.material, spheres), cut(g.spheres.texture, sphere_textures);
        cut(g.discs.centres, discs), cut(g.discs.normals, discs), cut(g.discs.material, discs);
        cut(g.discs.back_material, discs);
        TriangleMesh& m = g.mesh;
        cut(m.positions, positions), cut(m.normals, positions), cut(m.uvs, uvs), cut(m.triangles, triangles);
        cut(m.material, triangles), cut(m.back_material, triangles), cut(m.texture, mesh_textures);
    }

    std::size_t line_keys, line_v, line_segments, curve_points, curve_v, curve_segments, spheres,
        sphere_textures, discs, positions, uvs, triangles, mesh_textures;
};

Float3 place_point(const std::array<float, 12>& m, const Float3& p)
{
    return {m[0] * p[0] + m[3] * p[1] + m[6] * p[2] + m[9], m[1] * p[0] + m[4] * p[1] + m[7] * p[2] + m[10],
            m[2] * p[0] + m[5] * p[1] + m[8] * p[2] + m[11]};
}

/// A normal under the placement: by the inverse transpose of its 3x3 part (the
/// cofactor matrix over the determinant, of which only the sign matters), normalised.
Float3 place_normal(const std::array<float, 12>& m, const Float3& n)
{
    Vec3 x{m[0], m[1], m[2]}, y{m[3], m[4], m[5]}, z{m[6], m[7], m[8]};
    Vec3 r = cross(y, z) * n[0] + cross(z, x) * n[1] + cross(x, y) * n[2];
    if (dot(x, cross(y, z)) < 0)
        r = r * -1.0;
    double len = std::sqrt(dot(r, r));
    if (len == 0)
        return n;
    return {static_cast<float>(r.x / len), static_cast<float>(r.y / len), static_cast<float>(r.z / len)};
}

/// Appends a prototype's triangles placed by an instance (transform, materials in place
/// of inherit_material, texture for untextured triangles): a `~x` surface inside an
/// `-o>` object becomes part of the object's own geometry, since the renderer's
/// instances are one level deep. Surfaces are triangle meshes only.
void append_placed_mesh(TriangleMesh& into, const TriangleMesh& from, const Instance& instance)
{
    auto base = static_cast<std::uint32_t>(into.positions.size());
    for (std::size_t i = 0; i < from.positions.size(); ++i) {
        into.positions.push_back(place_point(instance.transform, from.positions[i]));
        into.normals.push_back(i < from.normals.size() ? place_normal(instance.transform, from.normals[i])
                                                       : Float3{0, 0, 0});
        into.uvs.push_back(i < from.uvs.size() ? from.uvs[i] : Float2{0, 0});
    }
    auto pick = [](std::uint16_t own, std::uint16_t inherited) {
        return own == inherit_material ? inherited : own;
    };
    for (std::size_t t = 0; t < from.triangles.size(); ++t) {
        const auto& tri = from.triangles[t];
        into.triangles.push_back({base + tri[0], base + tri[1], base + tri[2]});
        std::uint16_t front = t < from.material.size() ? from.material[t] : inherit_material;
        std::uint16_t back = t < from.back_material.size() ? from.back_material[t] : front;
        into.material.push_back(pick(front, instance.material));
        into.back_material.push_back(pick(back, instance.back_material));
        std::int16_t texture = t < from.texture.size() ? from.texture[t] : no_texture;
        into.texture.push_back(texture == no_texture ? instance.texture : texture);
    }
}

/// The placement of an object built in the turtle's starting frame (H = +y, L = -x,
/// U = -z at the origin): its x axis goes to -L, y to H, z to -U, the origin to the
/// turtle. No scale: the object was built with the first occurrence's turtle scale
/// (cpfg's rayshade output prints the same transformation).
std::array<float, 12> object_transform(const Turtle& t)
{
    auto f = [](double v) { return static_cast<float>(v); };
    return {f(-t.left.x), f(-t.left.y), f(-t.left.z), f(t.heading.x), f(t.heading.y), f(t.heading.z),
            f(-t.up.x),   f(-t.up.y),   f(-t.up.z),   f(t.position.x), f(t.position.y), f(t.position.z)};
}

/// One pass of the turtle over the string, cpfg's interpret.c semantics.
///
/// A segment's top width is the turtle's width when the segment ends, at the next
/// "node" (F f G g [ ] and the end of the string), so `F!F` tapers its first segment
/// (`tapered lines: on`, cpfg's default). Consecutive segments share their joint key,
/// which carries that width, and get Embree's neighbour flags.
/// Modules between two checks of the Scene's size against the memory budget: the
/// check sums a few dozen capacities, and the Scene grows by a few hundred bytes a module.
constexpr std::size_t memory_check_interval = 4096;

class Interpreter {
    /// A polygon vertex: the turtle's position and the frame its texture axes use.
    struct PolygonCorner {
        Vec3 position, heading, left;
        int color, back_color, texture;
    };

public:
    /// `root`: the interpreter of the whole string when this one builds an `-o>`
    /// object's prototype (it shares root's surfaces and places no objects itself).
    Interpreter(const ViewFile& view, const InterpretOptions& options, Interpreter* root = nullptr)
        : m_view(view), m_options(options), m_root(root ? root : this),
          m_cylinders(root ? root->m_cylinders.settings() : cylinder_settings(view), m_scene.geometry,
                      m_scene.bounds)  // the root's: its contour files are read once
    {
        m_turtle.cylinder.sides = m_cylinders.settings().sides;
        m_turtle.line_width = view.initial_line_width;
        m_turtle.color = view.initial_color;
        m_turtle.back_color = view.initial_back_color;
        m_turtle.scale = view.initial_scale;
        m_sub_scales.push_back(view.initial_scale);
        m_movements = std::span<const Movement>(view.movements.data(),
                                                std::min(view.movements.size(), Turtle::max_movements));
        if (view.movements.size() > Turtle::max_movements)
            warn("only the first " + std::to_string(Turtle::max_movements) +
                 " tropisms and torques are used");
        for (std::size_t i = 0; i < m_movements.size(); ++i)
            m_turtle.elasticity[i] = m_movements[i].initial_elasticity;
        m_turtle.legacy_elasticity = view.legacy_elasticity;
        m_scene.textures = view.textures;
        m_scene.line_radius_in_pixels = view.line_style == LineStyle::pixel;
        m_scene.view = view.view;
        m_scene.lights = effective_lights(view);
        m_scene.bounds.extend(Vec3{0, 0, 0});  // cpfg's box always holds the origin
        if (m_root == this) {
            load_surfaces();
            m_keying = object_keying(view);
            m_instancing = options.is_object && options.expand_object;
        }
    }

    void run(const lsys::ModuleString& string, const lsys::SymbolTable& symbols)
    {
        prepare(symbols);
        string.for_each([&](lsys::ModuleRef m) {
            interpret_module(m, m_root == this);
            ++m_module_index;
            if (m_root == this && m_module_index % memory_check_interval == 0)
                check_memory();
        });
        end_node();
        if (!m_polygons.empty())
            warn(std::to_string(m_polygons.size()) +
                 " polygon(s) left open at the end of the string are not drawn");
    }

    /// The Scene's arrays past the memory budget: an error rather than std::bad_alloc (or
    /// the system's OOM killer) later, in Embree.
    void check_memory() const
    {
        std::size_t bytes = geometry_bytes(m_scene.geometry);
        for (const Prototype& p : m_scene.prototypes)
            bytes += geometry_bytes(p.geometry);
        bytes += m_scene.instances.capacity() * sizeof(Instance);
        if (bytes > m_options.max_memory_bytes)
            throw Error("the scene's geometry needs " + byte_size_text(bytes) + " after " +
                        std::to_string(m_module_index) +
                        " modules of the string, more than the memory budget of " +
                        byte_size_text(m_options.max_memory_bytes) +
                        " (--max-memory); reduce the derivation length or raise --max-memory");
    }

    /// Records the answers of query modules (?P ?H ?L ?U) while interpreting.
    void collect_queries(std::vector<QueryAnswer>* answers) { m_answers = answers; }

    Scene take() { return std::move(m_scene); }

private:
    /// Per symbol of the string's table, looked up once (a prototype's builder uses its
    /// root's).
    struct SymbolTables {
        const lsys::SymbolTable* symbols = nullptr;
        std::vector<TurtleOp> ops;
        std::vector<int> surfaces;
        std::vector<char> objects;  ///< empty without object hooks
    };

    void prepare(const lsys::SymbolTable& symbols)
    {
        if (m_root != this) {
            m_tables = m_root->m_tables;
            return;
        }
        auto tables = std::make_shared<SymbolTables>();
        tables->symbols = &symbols;
        tables->ops = symbol_ops(symbols);
        tables->surfaces = surface_slots(symbols);
        if (m_options.is_object && m_options.expand_object) {
            tables->objects.resize(symbols.size());
            for (std::size_t id = 0; id < symbols.size(); ++id)
                tables->objects[id] = m_options.is_object(static_cast<lsys::SymbolId>(id)) ? 1 : 0;
        }
        m_tables = std::move(tables);
    }

    /// `top`: a module of the string itself. Modules of an object's expansion are never
    /// objects again: the homomorphism has already been applied to its full depth.
    void interpret_module(lsys::ModuleRef m, bool top)
    {
        const SymbolTables& t = *m_tables;
        if (top && !t.objects.empty() && t.objects[m.symbol]) {
            if (m_instancing)
                place_object(m);
            else
                interpret_expansion(*expansion(m));
        } else if (int slot = t.surfaces[m.symbol]; slot != not_a_surface) {
            draw_surface(slot, t.symbols->name(m.symbol)[1], m.params);
        } else {
            apply(t.ops[m.symbol], m.params);
        }
    }

    void interpret_expansion(const lsys::ModuleString& expansion)
    {
        expansion.for_each([&](lsys::ModuleRef x) { interpret_module(x, false); });
    }

    /// The homomorphism successor of an object module, kept per exact module (the hook
    /// depends on the module only) up to a bounded number of modules.
    std::shared_ptr<const lsys::ModuleString> expansion(lsys::ModuleRef m)
    {
        std::string exact(reinterpret_cast<const char*>(&m.symbol), sizeof m.symbol);
        exact.append(reinterpret_cast<const char*>(m.params.data()), m.params.size_bytes());
        if (auto it = m_expansions.find(exact); it != m_expansions.end())
            return it->second;
        auto e = std::make_shared<const lsys::ModuleString>(m_options.expand_object(m));
        if (m_cached_modules + e->size() > max_cached_expansion_modules) {
            m_expansions.clear();
            m_cached_modules = 0;
        }
        m_cached_modules += e->size() + 1;
        m_expansions.emplace(std::move(exact), e);
        return e;
    }

    /// An object module (manual 8.1): an instance of its prototype at the turtle, then
    /// the turtle goes through the expansion as cpfg's rayshade output does ("has to go
    /// through geometry to set turtle properly").
    void place_object(lsys::ModuleRef m)
    {
        std::shared_ptr<const lsys::ModuleString> e = expansion(m);
        int prototype = object_prototype(m, *e);
        if (prototype >= 0)
            m_scene.instances.push_back(Instance{static_cast<std::uint32_t>(prototype), object_transform(m_turtle),
                                                 material(m_turtle.color), material(m_turtle.back_color),
                                                 no_texture});  // a texture would reach untextured parts
        advance(*e);
    }

    /// The key cpfg's hash table compares: the module's name and its parameters printed
    /// with the `rayshade objects:` format, and with `turtle considered` the turtle's
    /// line width, scale, colours and texture.
    std::string object_key(lsys::ModuleRef m) const
    {
        std::string key = std::string(m_tables->symbols->name(m.symbol));
        char buffer[512];
        for (float p : m.params) {
            std::snprintf(buffer, sizeof buffer, m_keying.format.c_str(), static_cast<double>(p));
            key += '_';
            key += buffer;
        }
        if (m_keying.turtle_considered) {
            const Turtle& t = m_turtle;
            std::snprintf(buffer, sizeof buffer, "|%a|%a|%d|%d|%d", t.line_width, t.scale, t.color,
                          t.back_color, t.texture);
            key += buffer;
        }
        return key;
    }

    /// The prototype of an object key, built the first time from this occurrence's
    /// expansion in the turtle's starting frame with the current width, scale, colours
    /// and texture (cpfg's stage 2); -1 when it draws nothing.
    int object_prototype(lsys::ModuleRef m, const lsys::ModuleString& e)
    {
        std::string key = object_key(m);
        if (auto it = m_object_prototypes.find(key); it != m_object_prototypes.end())
            return it->second;
        Interpreter builder(m_view, m_options, this);
        builder.carry(m_turtle);
        builder.run(e, *m_tables->symbols);
        Scene built = builder.take();
        int index = -1;
        if (!built.geometry.empty()) {
            index = static_cast<int>(m_scene.prototypes.size());
            m_scene.prototypes.push_back(Prototype{key, std::move(built.geometry)});
        }
        m_object_prototypes.emplace(std::move(key), index);
        return index;
    }

    /// A prototype's builder starts with the placing turtle's drawing state.
    void carry(const Turtle& t)
    {
        m_turtle.line_width = t.line_width;
        m_turtle.scale = t.scale;
        m_turtle.color = t.color;
        m_turtle.back_color = t.back_color;
        m_turtle.texture = t.texture;
        m_sub_scales.back() = t.scale;
    }

    /// Interprets an object's expansion for its effect on the turtle, the bounds, the
    /// labels and polygons begun before it; the geometry it draws is the instance's and
    /// is cut away again.
    void advance(const lsys::ModuleString& e)
    {
        GeometrySizes before(m_scene.geometry);
        const Geometry& g = m_scene.geometry;
        std::optional<std::uint8_t> line_flag, curve_flag;
        if (!g.lines.flags.empty())
            line_flag = g.lines.flags.back();
        if (!g.curves.flags.empty())
            curve_flag = g.curves.flags.back();
        std::size_t instances = m_scene.instances.size();
        m_polygon_floor = m_polygons.size();
        m_advancing = true;
        interpret_expansion(e);
        m_advancing = false;
        bool drew_lines = m_scene.geometry.lines.keys.size() != before.line_keys;
        before.truncate(m_scene.geometry);
        if (line_flag)
            m_scene.geometry.lines.flags.back() = *line_flag;  // no longer continued
        if (curve_flag)
            m_scene.geometry.curves.flags.back() = *curve_flag;
        m_scene.instances.resize(instances);
        if (drew_lines) {
            m_chain_open = false;  // the last key was the object's
            m_taper_open = false;
        }
        for (const std::vector<PolygonCorner>& p : m_outer_polygons)
            emit_polygon(p);
        m_outer_polygons.clear();
    }

    static constexpr int not_a_surface = -1;
    static constexpr int undefined_surface = -2;

    /// The view file's `surface:` and `tsurface:` files, each a prototype of the scene.
    void load_surfaces()
    {
        m_surfaces = load_view_surfaces(m_view);
        for (SurfaceDef& def : m_surfaces) {
            m_surface_prototypes.push_back({static_cast<std::uint32_t>(m_scene.prototypes.size()), -1});
            m_scene.prototypes.push_back(std::move(def.prototype));
            def.prototype = Prototype{};
        }
    }

    /// The prototype of surface `slot` for a texture: textures with `S:` use a copy
    /// whose uvs span the whole surface, made the first time one is needed.
    std::uint32_t surface_prototype(int slot, std::int16_t texture)
    {
        auto s = static_cast<std::size_t>(slot);
        SurfacePrototypes& p = m_surface_prototypes[s];
        const std::vector<bool>& flags = m_view.texture_per_surface;
        auto t = static_cast<std::size_t>(texture);
        bool per_surface = texture >= 0 && t < flags.size() && flags[t];
        if (!per_surface)
            return p.per_patch;
        if (p.per_surface < 0) {
            Prototype copy = m_scene.prototypes[p.per_patch];
            if (copy.geometry.mesh.uvs.size() == m_surfaces[s].uvs_per_surface.size())
                copy.geometry.mesh.uvs = m_surfaces[s].uvs_per_surface;
            p.per_surface = static_cast<int>(m_scene.prototypes.size());
            m_scene.prototypes.push_back(std::move(copy));
        }
        return static_cast<std::uint32_t>(p.per_surface);
    }

    /// Per symbol: the index into m_surfaces of a `~x` module, undefined_surface for a
    /// `~x` whose letter no surface defines, not_a_surface otherwise.
    std::vector<int> surface_slots(const lsys::SymbolTable& symbols) const
    {
        std::vector<int> slots(symbols.size(), not_a_surface);
        for (std::size_t id = 0; id < symbols.size(); ++id) {
            std::string_view name = symbols.name(static_cast<lsys::SymbolId>(id));
            if (name.size() != 2 || name[0] != '~')
                continue;
            auto it = std::find_if(m_surfaces.begin(), m_surfaces.end(),
                                   [&](const SurfaceDef& d) { return d.letter == name[1]; });
            slots[id] = it == m_surfaces.end() ? undefined_surface
                                               : static_cast<int>(it - m_surfaces.begin());
        }
        return slots;
    }

    /// `~x`, `~x(s)`, `~x(sx, sy, sz)`: an instance of the surface at the turtle, then
    /// the turtle moves to its end point (cpfg ends the node first). cpfg's view volume
    /// takes the placed control points (vertices of a tsurface), unless a scale is 0.
    void draw_surface(int slot, char letter, std::span<const float> p)
    {
        end_node();
        if (slot == undefined_surface) {
            if (m_warned_surface_letters.find(letter) == std::string::npos) {
                warn(std::string("surface '~") + letter + "' is not defined in the view file; not drawn");
                m_warned_surface_letters += letter;
            }
            return;
        }
        const SurfaceDef& def = m_root->m_surfaces[static_cast<std::size_t>(slot)];
        const Turtle& t = m_turtle;
        Vec3 s = surface_scale(p, t.scale);
        if (s.x != 0 && s.y != 0 && s.z != 0) {
            std::int16_t texture = def.texture ? *def.texture : static_cast<std::int16_t>(t.texture);
            Instance instance{m_root->surface_prototype(slot, texture),
                              surface_instance_transform(def, t.position, t.heading, t.left, t.up, s),
                              material(t.color), material(t.back_color), texture};
            if (m_root == this)
                m_scene.instances.push_back(instance);
            else  // inside an object's prototype: instances are one level deep
                append_placed_mesh(m_scene.geometry.mesh,
                                   m_root->m_scene.prototypes[instance.prototype].geometry.mesh, instance);
            for (const Vec3& q : def.hull_points)
                m_scene.bounds.extend(t.position + t.left * (s.x * q.x) + t.heading * (s.y * q.y) +
                                      t.up * (s.z * q.z));
        }
        m_turtle.position = surface_end_position(def, t.position, t.heading, t.left, t.up, s.x);
        m_chain_open = false;
    }

    /// `@PS(i [, basis])`, `@PC(i, row, column)`, `@PD(i [, s, t])`: L-system patches.
    /// cpfg's view volume ignores them (the turtle has visited the control points).
    void patch_command(TurtleOp op, std::span<const float> p)
    {
        std::size_t needed = op == TurtleOp::PatchControl ? 3 : 1;
        if (p.size() < needed || !std::isfinite(p[0])) {
            warn_once(m_warned_patch, "@PS/@PC/@PD without a finite patch number are ignored");
            return;
        }
        // not finite: -1, which every use rejects or replaces with its default
        auto whole = [](float v) {
            return std::isfinite(v) ? static_cast<int>(std::clamp(v, -1e6f, 1e6f)) : -1;
        };
        if (op == TurtleOp::PatchStart)
            m_patches.start(p[0], p.size() >= 2 ? whole(p[1]) : 0);
        else if (op == TurtleOp::PatchControl)
            m_patches.set_control_point(p[0], whole(p[1]), whole(p[2]), m_turtle.position, FileLoc{});
        else
            m_patches.draw(p[0], p.size() >= 3 ? whole(p[1]) : 0, p.size() >= 3 ? whole(p[2]) : 0,
                           material(m_turtle.color), material(m_turtle.back_color),
                           static_cast<std::int16_t>(m_turtle.texture), m_scene.geometry.mesh, FileLoc{});
    }

    double angle(std::span<const float> p) const
    {
        return p.empty() ? m_view.angle_increment_deg : static_cast<double>(p[0]);
    }

    double length(std::span<const float> p) const
    {
        return (p.empty() ? 1.0 : static_cast<double>(p[0])) * m_turtle.scale;
    }

    void apply(TurtleOp op, std::span<const float> p)
    {
        switch (op) {
        case TurtleOp::None: break;
        case TurtleOp::Forward: draw_forward(length(p), true); break;
        case TurtleOp::ForwardG: draw_forward(length(p), false); break;
        case TurtleOp::ForwardNoDraw: move_forward(length(p), true); break;
        case TurtleOp::ForwardGNoDraw: move_forward(length(p), false); break;
        case TurtleOp::TurnLeft: m_turtle.turn(angle(p)); break;
        case TurtleOp::TurnRight: m_turtle.turn(-angle(p)); break;
        case TurtleOp::PitchDown: m_turtle.pitch(angle(p)); break;
        case TurtleOp::PitchUp: m_turtle.pitch(-angle(p)); break;
        case TurtleOp::RollRight: m_turtle.roll(angle(p)); break;
        case TurtleOp::RollLeft: m_turtle.roll(-angle(p)); break;
        case TurtleOp::TurnAround: m_turtle.turn_around(); break;
        case TurtleOp::Push: push(); break;
        case TurtleOp::Pop: pop(); break;
        case TurtleOp::WidthUp: change_width(p, +1); break;
        case TurtleOp::WidthDown: change_width(p, -1); break;
        case TurtleOp::ColorUp: change_color(p, +1); break;
        case TurtleOp::ColorDown: change_color(p, -1); break;
        case TurtleOp::BackColorUp: at_command(); change_back_color(p, +1); break;
        case TurtleOp::BackColorDown: at_command(); change_back_color(p, -1); break;
        case TurtleOp::MoveTo: at_command(); move_to(p); break;
        case TurtleOp::RollVertical: at_command(); m_turtle.roll_to_vertical(); break;
        case TurtleOp::SetHeading: at_command(); set_heading(p); break;
        case TurtleOp::Texture: at_command(); set_texture(p); break;
        case TurtleOp::ScaleSet:
        case TurtleOp::ScaleMultiply:
        case TurtleOp::ScaleDivide: at_command(); change_scale(op, p); break;
        case TurtleOp::Sphere: at_command(); draw_sphere(p); break;
        case TurtleOp::ScreenCircle: at_command(); draw_disc(p, true); break;
        case TurtleOp::Circle: at_command(); draw_disc(p, false); break;
        case TurtleOp::PolygonStart:
            end_node();  // cpfg ends the node at every `{`, with or without a type
            if (p.empty() || p[0] == 0)
                start_polygon();
            else
                m_cylinders.open_curve(m_turtle, p);  // {(type): a generalized cylinder
            break;
        case TurtleOp::PolygonEnd:
            if (p.empty() || p[0] == 0)
                end_polygon();
            else
                m_cylinders.close_curve(m_turtle);
            break;
        case TurtleOp::PolygonVertex:
            if (!m_polygons.empty())
                add_polygon_vertex();
            else if (m_turtle.cylinder.mode != CylinderMode::none)
                m_cylinders.control_point(m_turtle, p);  // cpfg: `.` outside polygons is @Gc
            break;
        case TurtleOp::ElasticitySet:
        case TurtleOp::ElasticityUp:
        case TurtleOp::ElasticityDown: at_command(); change_elasticity(op, p); break;
        case TurtleOp::LegacyElasticity:
            change_legacy_elasticity(m_turtle, p, m_view.legacy_elasticity_increment);
            break;
        case TurtleOp::PreventTwist: at_command(); m_turtle.adjust_up_and_left(); break;
        case TurtleOp::ForceTwist: at_command(); m_turtle.remember_frame(); break;
        case TurtleOp::SubLsystem: enter_sub_lsystem(p); break;
        case TurtleOp::SubLsystemEnd: leave_sub_lsystem(); break;
        case TurtleOp::Label: at_command(); add_label(p); break;
        case TurtleOp::SystemCall: at_command(); system_call(p); break;
        case TurtleOp::IncludeObject:
            at_command();
            warn_once(m_warned_include, "@I (rayshade object inclusion) is ignored");
            break;
        case TurtleOp::NewGrid:
            at_command();
            warn_once(m_warned_grid, "@J (rayshade grid) is ignored");
            break;
        case TurtleOp::QueryPosition: answer_query(p, m_turtle.position); break;
        case TurtleOp::QueryHeading: answer_query(p, m_turtle.heading); break;
        case TurtleOp::QueryLeft: answer_query(p, m_turtle.left); break;
        case TurtleOp::QueryUp: answer_query(p, m_turtle.up); break;
        case TurtleOp::CylinderStart: at_command(); m_cylinders.start(m_turtle); break;
        case TurtleOp::CylinderPoint: at_command(); m_cylinders.control_point(m_turtle, p); break;
        case TurtleOp::CylinderEnd: at_command(); m_cylinders.end(m_turtle, p); break;
        case TurtleOp::CylinderTangents: at_command(); CylinderBuilder::set_tangent_parameters(m_turtle, p); break;
        case TurtleOp::CylinderRadius: at_command(); CylinderBuilder::set_radius_tangents(m_turtle, p); break;
        case TurtleOp::CylinderContour: at_command(); m_cylinders.set_contour(m_turtle, p); break;
        case TurtleOp::CylinderSides: at_command(); m_cylinders.set_sides(m_turtle, p); break;
        case TurtleOp::PatchStart:
        case TurtleOp::PatchControl:
        case TurtleOp::PatchDraw: at_command(); patch_command(op, p); break;
        }
    }

    void warn_once(bool& warned, const std::string& message)
    {
        if (!warned)
            warn(message);
        warned = true;
    }

    /// Every `@` module ends the current node first (cpfg's interpret.c).
    void at_command() { end_node(); }

    /// `@M(x, y, z)`: cpfg's view volume records the new position.
    void move_to(std::span<const float> p)
    {
        if (p.size() < 2)
            return;
        m_turtle.position = Vec3{p[0], p[1], p.size() >= 3 ? p[2] : 0.0};
        m_scene.bounds.extend(m_turtle.position);
        m_chain_open = false;
    }

    void set_heading(std::span<const float> p)
    {
        if (p.size() < 2)
            return;
        Vec3 h{p[0], p[1], p.size() >= 3 ? p[2] : 0.0};
        if (p.size() >= 6)
            m_turtle.set_heading_and_up(h, Vec3{p[3], p[4], p[5]});
        else
            m_turtle.set_heading(h);
    }

    /// `@Tx(i)`: texture i-1 of the view file; 0, none or an unknown index: none.
    void set_texture(std::span<const float> p)
    {
        std::optional<int> number = p.empty() ? std::optional<int>(0) : whole_number(p[0]);
        if (!number)
            warn_once(m_warned_texture, "@Tx(" + text(p[0]) + "): no such texture; none used");
        int index = number.value_or(0) - 1;
        bool known = index >= 0 && static_cast<std::size_t>(index) < m_view.textures.size();
        m_turtle.texture = known ? index : -1;
    }

    /// A parameter in messages, as the L-system would print it.
    static std::string text(float v)
    {
        char buffer[32];
        std::snprintf(buffer, sizeof buffer, "%g", static_cast<double>(v));
        return buffer;
    }

    /// `@D(s)`, `@Di(f)`, `@Dd(f)`: set, multiply or divide the turtle scale.
    void change_scale(TurtleOp op, std::span<const float> p)
    {
        if (op == TurtleOp::ScaleSet) {
            if (p.empty())
                warn_once(m_warned_scale, "@D without its parameter is ignored");
            else
                m_turtle.scale = p[0];
            return;
        }
        double factor = p.empty() ? m_view.scale_multiplier : static_cast<double>(p[0]);
        if (factor == 0) {
            warn_once(m_warned_scale, "@Di/@Dd with factor 0 is ignored");
            return;
        }
        m_turtle.scale = op == TurtleOp::ScaleMultiply ? m_turtle.scale * factor : m_turtle.scale / factor;
    }

    /// The diameter of `@O`, `@o`, `@c`: the parameter times the scale, or the line width.
    double diameter(std::span<const float> p) const
    {
        return p.empty() ? m_turtle.line_width : static_cast<double>(p[0]) * m_turtle.scale;
    }

    std::uint16_t material(int color) const { return static_cast<std::uint16_t>(std::clamp(color, 0, 255)); }

    /// `@O(d)`: a sphere; cpfg's view volume takes the 8 corners of its cube.
    void draw_sphere(std::span<const float> p)
    {
        double r = std::abs(0.5 * diameter(p));  // cpfg draws -d as d
        Spheres& spheres = m_scene.geometry.spheres;
        spheres.centres.push_back(key(m_turtle.position, static_cast<float>(r)));
        spheres.material.push_back(material(m_turtle.color));
        spheres.texture.push_back(no_texture);  // cpfg maps no texture on spheres
        for (int x = -1; x <= 1; x += 2)
            for (int y = -1; y <= 1; y += 2)
                for (int z = -1; z <= 1; z += 2)
                    m_scene.bounds.extend(m_turtle.position + Vec3{x * r, y * r, z * r});
    }

    /// `@o(d)`: a disc facing the viewer; `@c(d)`: a disc in the HL plane, its front
    /// toward U. cpfg's view volume takes four corners in x and y, at z = 0 for `@o`
    /// and at the turtle's z for `@c`.
    void draw_disc(std::span<const float> p, bool facing_viewer)
    {
        double r = std::abs(0.5 * diameter(p));
        Vec3 normal = facing_viewer ? normalize(m_view.view.viewpoint - m_view.view.reference_point)
                                    : normalize(m_turtle.up);
        if (dot(normal, normal) == 0)
            normal = Vec3{0, 0, 1};
        Discs& discs = m_scene.geometry.discs;
        discs.centres.push_back(key(m_turtle.position, static_cast<float>(r)));
        discs.normals.push_back({static_cast<float>(normal.x), static_cast<float>(normal.y),
                                 static_cast<float>(normal.z)});
        discs.material.push_back(material(m_turtle.color));
        discs.back_material.push_back(material(m_turtle.back_color));
        double z = facing_viewer ? 0.0 : m_turtle.position.z;
        for (int x = -1; x <= 1; x += 2)
            for (int y = -1; y <= 1; y += 2)
                m_scene.bounds.extend(Vec3{m_turtle.position.x + x * r, m_turtle.position.y + y * r, z});
    }

    /// `{`: a new polygon on the polygon stack (independent of the turtle stack, so a
    /// polygon may collect vertices across branches).
    void start_polygon()
    {
        end_node();
        if (m_polygons.size() >= max_open_polygons)
            throw Error("more than " + std::to_string(max_open_polygons) + " nested polygons");
        m_polygons.emplace_back();
    }

    void add_polygon_vertex()
    {
        if (m_polygons.back().size() >= max_polygon_vertices)
            throw Error("a polygon with more than " + std::to_string(max_polygon_vertices) +
                                       " vertices");
        m_polygons.back().push_back({m_turtle.position, m_turtle.heading, m_turtle.left,
                                     m_turtle.color, m_turtle.back_color, m_turtle.texture});
    }

    /// `}`: triangulates the innermost polygon.
    void end_polygon()
    {
        if (m_polygons.empty()) {
            warn_once(m_warned_unmatched_polygon, "unmatched '}' in the string ignored");
            return;
        }
        end_node();
        if (m_advancing && m_polygons.size() <= m_polygon_floor) {
            // begun before an object and closed in it: the scene's own polygon
            m_outer_polygons.push_back(std::move(m_polygons.back()));
            m_polygon_floor = m_polygons.size() - 1;
        } else {
            emit_polygon(m_polygons.back());
        }
        m_polygons.pop_back();
    }

    /// Materials and texture are the first vertex's (as cpfg's rayshade output
    /// takes them); texture coordinates come from its frame (report 5.3): u along
    /// R = -L, v along H, each scaled to [0, 1] over the polygon.
    void emit_polygon(const std::vector<PolygonCorner>& corners)
    {
        std::vector<Vec3> outline;
        outline.reserve(corners.size());
        for (const PolygonCorner& c : corners)
            outline.push_back(c.position);
        bool cut_short = false;
        auto triangles = triangulate_polygon(outline, &cut_short);
        if (cut_short)
            warn("a polygon of " + std::to_string(outline.size()) +
                 " vertices took too long to triangulate; the rest of it was cut in order "
                 "(concave parts may be filled wrongly)");
        if (triangles.empty())
            return;
        Vec3 n = polygon_normal(outline);
        Vec3 s_axis = -corners[0].left, t_axis = corners[0].heading;
        double s_lo = 1e300, s_hi = -1e300, t_lo = 1e300, t_hi = -1e300;
        for (const Vec3& q : outline) {
            s_lo = std::min(s_lo, dot(q, s_axis));
            s_hi = std::max(s_hi, dot(q, s_axis));
            t_lo = std::min(t_lo, dot(q, t_axis));
            t_hi = std::max(t_hi, dot(q, t_axis));
        }
        auto unit = [](double x, double lo, double hi) {
            return hi > lo ? static_cast<float>((x - lo) / (hi - lo)) : 0.f;
        };
        auto f3 = [](const Vec3& v) {
            return Float3{static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z)};
        };
        TriangleMesh& mesh = m_scene.geometry.mesh;
        auto base = static_cast<std::uint32_t>(mesh.positions.size());
        for (const Vec3& q : outline) {
            mesh.positions.push_back(f3(q));
            mesh.normals.push_back(f3(n));
            mesh.uvs.push_back({unit(dot(q, s_axis), s_lo, s_hi), unit(dot(q, t_axis), t_lo, t_hi)});
        }
        for (const auto& t : triangles) {
            mesh.triangles.push_back({base + t[0], base + t[1], base + t[2]});
            mesh.material.push_back(material(corners[0].color));
            mesh.back_material.push_back(material(corners[0].back_color));
            mesh.texture.push_back(static_cast<std::int16_t>(corners[0].texture));
        }
    }

    /// `@Ts(i, e)`, `@Ti(i [, d])`, `@Td(i [, d])`: tropism i (from 1; 0 parameters:
    /// the first). `@Ts(i)` sets 0; `@Ti`/`@Td` without d use the tropism's S: step.
    void change_elasticity(TurtleOp op, std::span<const float> p)
    {
        int index = p.empty() ? 0 : whole_number(p[0]).value_or(0) - 1;
        if (index < 0 || static_cast<std::size_t>(index) >= m_movements.size()) {
            warn_once(m_warned_movement, "tropism index out of range in @Ts/@Ti/@Td ignored");
            return;
        }
        double& e = m_turtle.elasticity[static_cast<std::size_t>(index)];
        double step = p.size() >= 2 ? static_cast<double>(p[1])
                                    : m_movements[static_cast<std::size_t>(index)].elasticity_step;
        if (op == TurtleOp::ElasticitySet)
            e = p.size() >= 2 ? static_cast<double>(p[1]) : 0.0;
        else if (op == TurtleOp::ElasticityUp)
            e += step;
        else
            e -= step;
    }

    /// `?(id, s)`: the scale is multiplied by s (kept on its own stack), the line
    /// width follows; `$` restores both (cpfg's UpdateCurrentLsystem).
    void enter_sub_lsystem(std::span<const float> p)
    {
        if (p.empty())
            return;
        if (m_sub_scales.size() >= max_sub_lsystem_depth)
            throw Error("sub-L-systems nested deeper than " + std::to_string(max_sub_lsystem_depth));
        double old_scale = m_sub_scales.back();
        double new_scale = p.size() >= 2 ? old_scale * p[1] : old_scale;
        m_sub_scales.push_back(new_scale);
        rescale(old_scale, new_scale);
    }

    void leave_sub_lsystem()
    {
        if (m_sub_scales.size() <= 1) {
            warn_once(m_warned_unmatched_sub, "unmatched '$' in the string ignored");
            return;
        }
        double old_scale = m_sub_scales.back();
        m_sub_scales.pop_back();
        rescale(old_scale, m_sub_scales.back());
    }

    void rescale(double old_scale, double new_scale)
    {
        m_turtle.scale = new_scale;
        if (old_scale != 0)
            m_turtle.line_width = m_turtle.line_width * new_scale / old_scale;
    }

    /// @S("command"): handed to InterpretOptions::system_call when the user allowed it.
    void system_call(std::span<const float> p)
    {
        if (!m_options.system_call) {
            warn_once(m_warned_system, "@S system calls are not run; use --allow-system-calls");
            return;
        }
        if (p.empty() || !(p[0] >= 0) || static_cast<std::size_t>(p[0]) >= m_options.strings.size()) {
            warn_once(m_warned_system, "@S without a command string (@S(\"command\")) is ignored");
            return;
        }
        m_options.system_call(m_options.strings[static_cast<std::size_t>(p[0])]);
    }

    /// `@L(text [, values...])`: a label; the text's printf conversions take the values.
    void add_label(std::span<const float> p)
    {
        Label label;
        label.position = m_turtle.position;
        label.material = material(m_turtle.color);
        std::optional<int> string = p.empty() ? std::nullopt : whole_number(p[0]);
        if (string && *string >= 0 && static_cast<std::size_t>(*string) < m_options.strings.size())
            label.text = format_label(m_options.strings[static_cast<std::size_t>(*string)], p.subspan(1));
        else if (!m_options.strings.empty() || !p.empty())
            warn_once(m_warned_label, "@L without a known string: label text left empty");
        m_scene.labels.push_back(std::move(label));
    }

    /// Replaces each printf conversion (%g %f %d %e...) with the next value.
    static std::string format_label(const std::string& format, std::span<const float> values)
    {
        std::string out;
        std::size_t next = 0;
        for (std::size_t i = 0; i < format.size(); ++i) {
            if (format[i] != '%' || i + 1 >= format.size()) {
                out += format[i];
                continue;
            }
            if (format[i + 1] == '%') {
                out += '%';
                ++i;
                continue;
            }
            // only flags, width and precision may stand between '%' and the conversion
            std::size_t end = format.find_first_not_of("-+ #0123456789.", i + 1);
            if (end == std::string::npos || end - i > 12 ||
                std::string_view("diouxXeEfFgG").find(format[end]) == std::string_view::npos) {
                out += format[i];
                continue;
            }
            std::string spec = format.substr(i, end - i + 1);
            double value = next < values.size() ? static_cast<double>(values[next++]) : 0.0;
            char buffer[128];
            char conversion = format[end];
            // an integer conversion of a value no long long holds prints it as %g
            bool integral = std::abs(value) < 9e18;
            if (std::string_view("diouxX").find(conversion) != std::string_view::npos && integral)
                std::snprintf(buffer, sizeof buffer, (spec.substr(0, spec.size() - 1) + "lld").c_str(),
                              static_cast<long long>(value));
            else if (!integral)
                std::snprintf(buffer, sizeof buffer, (spec.substr(0, spec.size() - 1) + "g").c_str(), value);
            else
                std::snprintf(buffer, sizeof buffer, spec.c_str(), value);
            out += buffer;
            i = end;
        }
        return out;
    }

    /// `?P` `?H` `?L` `?U`: the first two or three parameters get the vector.
    void answer_query(std::span<const float> p, const Vec3& v)
    {
        if (!m_answers || p.empty())
            return;
        m_answers->push_back({m_module_index, {static_cast<float>(v.x), static_cast<float>(v.y),
                                               static_cast<float>(v.z)}});
    }

    /// Ends the current node: the last segment's top width is now fixed, and the
    /// turtle's position goes into the bounding box as cpfg's viewVol.c records it.
    void end_node()
    {
        m_taper_open = false;
        m_scene.bounds.extend(m_turtle.position);
    }

    void push()
    {
        end_node();
        m_stack.push_back(m_turtle);
    }

    void pop()
    {
        end_node();
        if (m_stack.empty()) {
            if (!m_warned_unbalanced)
                warn("unmatched ']' in the string ignored");
            m_warned_unbalanced = true;
            return;
        }
        m_turtle = m_stack.back();
        m_stack.pop_back();
        m_chain_open = false;
    }

    /// `#` and `!`: by the view file's increment, or set to the parameter; at least 1e-7.
    void change_width(std::span<const float> p, int sign)
    {
        double width = p.empty() ? m_turtle.line_width + sign * m_view.line_width_increment * m_turtle.scale
                                 : static_cast<double>(p[0]) * m_turtle.scale;
        width = std::max(width, 1e-7);
        if (width == m_turtle.line_width)
            return;
        m_turtle.line_width = width;
        if (m_taper_open && tapers())
            m_scene.geometry.lines.keys.back()[3] = radius();  // the open segment's top
        else
            m_chain_open = false;  // the joint key cannot carry two widths
    }

    /// `@;` and `@,`: the back colour, by the second colour increment or set; only
    /// when `initial color:` gave two indices (otherwise the back follows the front).
    void change_back_color(std::span<const float> p, int sign)
    {
        if (!m_view.separate_back_color)
            return;
        std::optional<int> set = p.empty() ? std::nullopt : whole_number(p[0]);
        if (!p.empty() && !set) {
            warn_once(m_warned_color, "colour index " + text(p[0]) + " out of range in ;(n) ,(n) @;(n) @,(n) ignored");
            return;
        }
        int color = set ? *set : m_turtle.back_color + sign * m_view.back_color_increment;
        if (color > 255)
            color -= 256;
        if (color < 0)
            color += 256;
        m_turtle.back_color = std::clamp(color, -1'000'000'000, 1'000'000'000);  // no int overflow next
    }

    /// `;` and `,`: by the increment (wrapping once around the 256 entries) or set.
    void change_color(std::span<const float> p, int sign)
    {
        std::optional<int> set = p.empty() ? std::nullopt : whole_number(p[0]);
        if (!p.empty() && !set) {
            warn_once(m_warned_color, "colour index " + text(p[0]) + " out of range in ;(n) ,(n) @;(n) @,(n) ignored");
            return;
        }
        int color = set ? *set : m_turtle.color + sign * m_view.color_increment;
        if (color > 255)
            color -= 256;
        if (color < 0)
            color += 256;
        m_turtle.color = std::clamp(color, -1'000'000'000, 1'000'000'000);  // no int overflow next
        // Manual 5.1.9: sides differ only when `initial color:` gives two indices.
        if (!m_view.separate_back_color)
            m_turtle.back_color = color;
    }

    bool tapers() const { return m_view.tapered_lines && !m_scene.line_radius_in_pixels; }

    float radius() const { return static_cast<float>(0.5 * m_turtle.line_width); }

    /// f and g. The order is cpfg's: tropisms turn the heading, the node ends, the
    /// turtle moves, the legacy tropism bends it, texture v advances, and f records a
    /// polygon vertex.
    void move_forward(double distance, bool polygon_vertex)
    {
        apply_movements(m_turtle, m_movements);
        end_node();
        m_turtle.position += m_turtle.heading * distance;
        after_move(distance, polygon_vertex);
        m_chain_open = false;
    }

    void after_move(double distance, bool polygon_vertex)
    {
        legacy_bend();
        m_turtle.texture_v += texture_advance(distance);
        if (polygon_vertex && !m_polygons.empty())
            add_polygon_vertex();
        if (polygon_vertex)
            m_cylinders.moved(m_turtle);  // F and f are control points after {(type)
    }

    /// cpfg's bend(): the pre-3.0 tropism turns H toward U, then toward L, by the
    /// angles whose sines are e T.U and e T.L (clamped to [-1, 1]).
    void legacy_bend()
    {
        double e = m_turtle.legacy_elasticity;
        if (e == 0)
            return;
        const Vec3& t = m_view.legacy_tropism_direction;
        double s = std::clamp(e * dot(t, m_turtle.up), -1.0, 1.0);
        m_turtle.pitch(std::asin(s) * 180.0 / std::numbers::pi);
        s = std::clamp(e * dot(t, m_turtle.left), -1.0, 1.0);
        m_turtle.turn(std::asin(s) * 180.0 / std::numbers::pi);
    }

    /// Texture v gained over a step (report 5.2, cpfg's update_segment_texture):
    /// length / (pi width R) while a texture is selected. The image's width/height
    /// factor is left to the renderer (it knows the image).
    double texture_advance(double distance) const
    {
        if (m_turtle.texture < 0 || m_turtle.line_width == 0)
            return 0;
        double ratio = static_cast<std::size_t>(m_turtle.texture) < m_view.texture_aspect_ratios.size()
                           ? m_view.texture_aspect_ratios[static_cast<std::size_t>(m_turtle.texture)]
                           : 1.0;
        return distance / (std::numbers::pi * m_turtle.line_width) / ratio;
    }

    /// Draws one cylinder segment, continuing the current polyline when the turtle
    /// has drawn without interruption, so Embree closes the joint.
    void draw_forward(double distance, bool polygon_vertex)
    {
        apply_movements(m_turtle, m_movements);
        end_node();
        Vec3 start = m_turtle.position;
        double start_v = m_turtle.texture_v;
        m_turtle.position += m_turtle.heading * distance;
        after_move(distance, polygon_vertex);
        LinearCurves& lines = m_scene.geometry.lines;
        bool joined = m_chain_open;
        if (!joined) {
            lines.keys.push_back(key(start, radius()));
            lines.v.push_back(static_cast<float>(start_v));
        }
        auto first = static_cast<std::uint32_t>(lines.keys.size() - 1);
        lines.keys.push_back(key(m_turtle.position, radius()));
        lines.v.push_back(static_cast<float>(m_turtle.texture_v));
        if (joined)
            lines.flags.back() |= LinearCurves::neighbour_right;
        lines.segments.push_back(first);
        lines.flags.push_back(joined ? LinearCurves::neighbour_left : 0);
        lines.material.push_back(material(m_turtle.color));
        lines.texture.push_back(static_cast<std::int16_t>(m_turtle.texture));
        m_turtle.remember_frame();  // F and G: the reference for twist-free adjustments
        m_chain_open = true;
        m_taper_open = true;
    }

    static std::array<float, 4> key(const Vec3& p, float radius)
    {
        return {static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z), radius};
    }

    static constexpr std::size_t max_open_polygons = 100'000;
    static constexpr std::size_t max_polygon_vertices = 10'000'000;
    static constexpr std::size_t max_sub_lsystem_depth = 100'000;

    static constexpr std::size_t max_cached_expansion_modules = 4'000'000;

    const ViewFile& m_view;
    InterpretOptions m_options;
    Interpreter* m_root;  ///< this, or the interpreter whose object this one builds
    Scene m_scene;
    Turtle m_turtle;
    CylinderBuilder m_cylinders;  ///< generalized cylinders, into m_scene
    std::vector<Turtle> m_stack;
    std::span<const Movement> m_movements;
    std::vector<std::vector<PolygonCorner>> m_polygons;  ///< cpfg's polygon stack
    std::vector<double> m_sub_scales;                    ///< cpfg's sub-L-system scale stack
    std::vector<QueryAnswer>* m_answers = nullptr;
    std::vector<SurfaceDef> m_surfaces;                  ///< their prototypes moved out
    struct SurfacePrototypes {
        std::uint32_t per_patch;  ///< uvs per patch (cpfg's default)
        int per_surface;          ///< uvs over the surface, for `S:` textures; -1: not made
    };
    std::vector<SurfacePrototypes> m_surface_prototypes;  ///< per surface
    LsystemPatches m_patches;
    std::shared_ptr<const SymbolTables> m_tables;
    // `-o>` objects (root only)
    ObjectKeying m_keying;
    bool m_instancing = false;
    std::unordered_map<std::string, int> m_object_prototypes;  ///< key -> prototype, -1: empty
    std::unordered_map<std::string, std::shared_ptr<const lsys::ModuleString>> m_expansions;
    std::size_t m_cached_modules = 0;
    bool m_advancing = false;              ///< inside advance(): geometry is cut afterwards
    std::size_t m_polygon_floor = 0;       ///< polygons below this index began before the object
    std::vector<std::vector<PolygonCorner>> m_outer_polygons;
    std::size_t m_module_index = 0;
    bool m_warned_system = false, m_warned_include = false, m_warned_grid = false;
    bool m_warned_scale = false, m_warned_unmatched_polygon = false, m_warned_movement = false;
    bool m_warned_unmatched_sub = false, m_warned_label = false;
    bool m_warned_patch = false, m_warned_texture = false, m_warned_color = false;
    std::string m_warned_surface_letters;  ///< undefined `~x` letters already reported
    bool m_chain_open = false;  ///< the last key is at the turtle and may be shared
    bool m_taper_open = false;  ///< the last segment's top width may still change
    bool m_warned_unbalanced = false;
};

}  // namespace

ObjectKeying object_keying(const ViewFile& view)
{
    ObjectKeying keying;
    for (const ViewCommand& c : view.deferred) {
        if (c.name != "rayshade objects")
            continue;
        // cpfg's rsReadViewCommand: tokens split at blanks and colons
        std::string text = c.value;
        std::replace(text.begin(), text.end(), ':', ' ');
        std::istringstream in(text);
        std::string format, word, flag;
        if (!(in >> format))
            continue;
        if (is_float_format(format))
            keying.format = format;
        else
            warn(c.loc, "rayshade objects: '" + format + "' is not a printf format of one number; using %g");
        if (in >> word >> flag && word == "turtle" && flag.starts_with("considered"))
            keying.turtle_considered = true;
    }
    return keying;
}

std::vector<Light> effective_lights(const ViewFile& view)
{
    if (!view.lights.empty())
        return view.lights;
    // cpfg's default: a white directional light toward `light direction:`, (1,0,0).
    Light light;
    light.kind = Light::Kind::directional;
    light.direction = normalize(view.light_direction.value_or(Vec3{1, 0, 0}));
    return {light};
}

Scene interpret(const lsys::ModuleString& string, const lsys::SymbolTable& symbols,
                const ViewFile& view)
{
    return interpret(string, symbols, view, InterpretOptions{});
}

Scene interpret(const lsys::ModuleString& string, const lsys::SymbolTable& symbols,
                const ViewFile& view, const InterpretOptions& options)
{
    Interpreter interpreter(view, options);
    interpreter.run(string, symbols);
    return interpreter.take();
}

std::vector<QueryAnswer> collect_query_answers(const lsys::ModuleString& string,
                                               const lsys::SymbolTable& symbols,
                                               const ViewFile& view)
{
    std::vector<QueryAnswer> answers;
    Interpreter interpreter(view, InterpretOptions{});
    interpreter.collect_queries(&answers);
    interpreter.run(string, symbols);
    return answers;
}

}  // namespace cambium::geom
