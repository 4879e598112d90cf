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

#include "geom/gls_polygons.h"
#include "geom/label.h"
#include "geom/object_instancing.h"
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
        std::size_t opened_at;  ///< the string index of the polygon's `{` (provenance)
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
        m_past_cut = view.interprets_past_cut;
        m_polygon_outlines = view.render_mode.shading == Shading::wireframe;
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
        m_scene.label_font = view.font;
        m_scene.bounds.extend(Vec3{0, 0, 0});  // cpfg's box always holds the origin
        m_provenance = m_root == this && options.provenance && !options.bounds_only;
        if (m_root == this) {
            load_surfaces();
            if (options.is_object && options.expand_object)
                m_objects = std::make_unique<ObjectInstancer>(view, options.expand_object);
        }
    }

    void run(const lsys::ModuleString& string, const lsys::SymbolTable& symbols)
    {
        prepare(symbols);
        m_string = &string;
        string.for_each([&](lsys::ModuleRef m) {
            if (skipped_after_cut(m)) {
            } else if (static_cast<int>(m.symbol) == m_tables->cut && !m.params.empty() &&
                       m_root == this) {
                fragment_module(m);
            } else {
                if (m_capture)
                    begin_captures();
                if (m_provenance && m_options.branch_orders)
                    note_module_depth();
                interpret_module(m, m_root == this);
            }
            if (m_provenance)
                attribute(m_module_index);
            ++m_module_index;
            if (m_capture)
                end_captures();
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
        bytes += m_label_text_bytes + m_scene.labels.capacity() * sizeof(Label);
        // a string of nested '[' holds a turtle each without drawing anything
        const std::size_t stack_bytes = m_stack.capacity() * sizeof(Turtle);
        if (bytes <= m_options.max_memory_bytes && bytes + stack_bytes > m_options.max_memory_bytes)
            throw Error("the turtle's branch stack of " + std::to_string(m_stack.size()) +
                        " nested '[' needs " + byte_size_text(stack_bytes) + " after " +
                        std::to_string(m_module_index) +
                        " modules of the string, beside the geometry more than the memory budget of " +
                        byte_size_text(m_options.max_memory_bytes) +
                        " (--max-memory); close the branches or raise --max-memory");
        if (bytes > m_options.max_memory_bytes)
            throw Error("the scene's geometry needs " + byte_size_text(bytes) + " after " +
                        std::to_string(m_module_index) +
                        " modules of the string, more than the memory budget of " +
                        byte_size_text(m_options.max_memory_bytes) +
                        " (--max-memory); reduce the derivation length or raise --max-memory");
    }

    /// Saves the turtle at each one-parameter `%` into `fresh` (at most `limit`) and
    /// records those modules' indices into `starts` (save_fragment_turtles).
    void collect_fragments(std::vector<Turtle>* fresh, std::vector<std::uint32_t>* starts,
                           std::size_t limit)
    {
        m_fresh_turtles = fresh;
        m_fragment_starts = starts;
        m_fresh_limit = limit;
    }

    /// Records the answers of query modules (?P ?H ?L ?U) while interpreting.
    void collect_queries(std::vector<QueryAnswer>* answers) { m_answers = answers; }

    /// Records the turtle at each communication module ?E while interpreting.
    void collect_communication(std::vector<TurtleAtModule>* turtles) { m_communication = turtles; }

    /// Records, for each range of modules (sorted by begin), the polygons its modules
    /// draw: polygons[k] for ranges[k].
    void collect_polygons(std::span<const ModuleRange> ranges,
                          std::vector<std::vector<GlsPolygon>>* polygons)
    {
        polygons->assign(ranges.size(), {});
        m_capture = ranges.empty() ? nullptr : polygons;
        m_capture_ranges = ranges;
    }

    Scene take() { return std::move(m_scene); }

private:
    /// Per symbol of the string's table, looked up once (a prototype's builder uses its
    /// root's).
    struct SymbolTables {
        const lsys::SymbolTable* symbols = nullptr;
        std::vector<TurtleOp> ops;
        std::vector<int> surfaces;
        std::vector<char> objects;  ///< empty without object hooks
        int cut = -1, conditional_cut = -1;  ///< `%` and `@mc`, if the string has them
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
        tables->cut = symbols.find("%");
        tables->conditional_cut = symbols.find("@mc");
        if (m_options.is_object && m_options.expand_object) {
            tables->objects.resize(symbols.size());
            for (std::size_t id = 0; id < symbols.size(); ++id)
                tables->objects[id] = m_options.is_object(static_cast<lsys::SymbolId>(id)) ? 1 : 0;
        }
        m_tables = std::move(tables);
    }

    /// `%` with parameters (manual 5.1.9): `%(par, index)` sets the turtle saved at its
    /// fragment's start, as `]` sets the one saved at `[`; the fragment pass saves the
    /// turtle at each `%(par)`.
    void fragment_module(lsys::ModuleRef m)
    {
        if (m.params.size() == 1) {
            if (!m_fresh_turtles)
                return;
            if (m_fresh_turtles->size() >= m_fresh_limit)
                throw Error("more than " + std::to_string(m_fresh_limit) +
                            " turtles saved at fragment starts %(par) (manual 5.1.9)");
            m_fresh_turtles->push_back(m_turtle);
            m_fragment_starts->push_back(static_cast<std::uint32_t>(m_module_index));
            return;
        }
        const std::span<const Turtle> saved = m_options.fragment_turtles;
        const double index = m.params[1];
        if (!(index >= 0 && index < static_cast<double>(saved.size())) || index != std::floor(index)) {
            if (!m_warned_fragment)
                warn("%(par, index): no turtle was saved under index " + std::to_string(index) +
                     " (only a fragment moved by derivation has one); the turtle is kept");
            m_warned_fragment = true;
            return;
        }
        end_node();
        m_turtle = saved[static_cast<std::size_t>(index)];
        m_chain_open = false;
    }

    /// Under `interpretation past %: off`, a cut (`%`, or `@mc(1)`: manual 5.1.9) and
    /// everything after it up to the ']' that ends its branch are skipped; that ']' is
    /// interpreted, so the turtle state comes back as after the whole branch.
    bool skipped_after_cut(lsys::ModuleRef m)
    {
        const SymbolTables& t = *m_tables;
        if (m_cut_depth >= 0) {
            TurtleOp op = t.ops[m.symbol];
            if (static_cast<int>(m.symbol) == t.cut && !m.params.empty()) {
                m_cut_depth = -1;  // cpfg's skip also ends at a `%` with parameters
                return false;
            }
            if (op == TurtleOp::Push)
                ++m_cut_depth;
            else if (op == TurtleOp::Pop && m_cut_depth-- == 0)
                return false;  // the branch's end: m_cut_depth is -1 again
            return true;
        }
        bool cut = (static_cast<int>(m.symbol) == t.cut && m.params.empty()) ||
                   (static_cast<int>(m.symbol) == t.conditional_cut && !m.params.empty() &&
                    m.params[0] == 1.0f);
        if (m_past_cut || !cut)
            return false;
        m_cut_depth = 0;
        return true;
    }

    /// `top`: a module of the string itself. Modules of an object's expansion are never
    /// objects again: the homomorphism has already been applied to its full depth.
    void interpret_module(lsys::ModuleRef m, bool top)
    {
        const SymbolTables& t = *m_tables;
        if (top && !t.objects.empty() && t.objects[m.symbol]) {
            place_object(m);
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

    /// An object module (manual 8.1): an instance of its prototype at the turtle, then
    /// the turtle goes through the expansion as cpfg's rayshade output does ("has to go
    /// through geometry to set turtle properly").
    void place_object(lsys::ModuleRef m)
    {
        std::shared_ptr<const lsys::ModuleString> e = m_objects->expansion(m);
        // the prototype is built in the turtle's starting frame with this occurrence's
        // width, scale, colours and texture
        auto build = [&] {
            Interpreter builder(m_view, m_options, this);
            builder.carry(m_turtle);
            builder.run(*e, *m_tables->symbols);
            return std::move(builder.take().geometry);
        };
        int prototype = m_objects->prototype(m_objects->key(m_tables->symbols->name(m.symbol), m, m_turtle),
                                             m_scene, build);
        if (prototype >= 0)
            m_scene.instances.push_back(Instance{static_cast<std::uint32_t>(prototype), object_transform(m_turtle),
                                                 material(m_turtle.color), material(m_turtle.back_color),
                                                 no_texture, no_module, Instance::no_plant});  // a texture would reach untextured parts
        advance(*e);
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
        GeometryCheckpoint before(m_scene.geometry);
        std::size_t instances = m_scene.instances.size();
        m_polygon_floor = m_polygons.size();
        m_advancing = true;
        interpret_expansion(e);
        m_advancing = false;
        if (before.restore(m_scene.geometry)) {
            m_chain_open = false;  // the last key was the object's
            m_taper_open = false;
        }
        m_scene.instances.resize(instances);
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
            if (m_options.surface_material_offset != 0)
                apply_patch_colours(def);
            m_surface_prototypes.push_back({static_cast<std::uint32_t>(m_scene.prototypes.size()), -1});
            m_scene.prototypes.push_back(std::move(def.prototype));
            def.prototype = Prototype{};
        }
    }

    /// Colormap-mode lighting: a patch with its own colours takes their materials
    /// instead of the instance's (cpfg's determine_vertex_shading).
    void apply_patch_colours(SurfaceDef& def) const
    {
        TriangleMesh& mesh = def.prototype.geometry.mesh;
        for (std::size_t t = 0; t < def.patch_colours.size() && t < mesh.material.size(); ++t) {
            const PatchColours& c = def.patch_colours[t];
            if (c.top != 0)
                mesh.material[t] = patch_material(c.top);
            if (c.bottom != 0)
                mesh.back_material[t] = patch_material(c.bottom);
        }
    }

    /// The material of patch colour `colour` (not 0): past 255 it lies in the next
    /// colormap; past 511 it is clamped there (docs/deviations.md).
    std::uint16_t patch_material(int colour) const
    {
        if (colour < 256 || m_options.next_colormap_material_offset == 0)
            return surface_material(colour);
        return static_cast<std::uint16_t>(m_options.next_colormap_material_offset +
                                          std::min(colour - 256, 255));
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
                              surface_material(t.color), surface_material(t.back_color), texture};
            if (m_options.bounds_only)
                ;  // nothing stored
            else if (m_root == this)
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
        else if (!m_options.bounds_only)
            m_patches.draw(p[0], p.size() >= 3 ? whole(p[1]) : 0, p.size() >= 3 ? whole(p[2]) : 0,
                           surface_material(m_turtle.color), surface_material(m_turtle.back_color),
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
        case TurtleOp::Communicate:
            if (m_communication)
                m_communication->push_back({m_module_index, m_turtle.position, m_turtle.heading,
                                            m_turtle.left, m_turtle.up, m_turtle.line_width,
                                            m_turtle.scale});
            break;
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
    /// The material of a predefined surface or patch of colour `color`.
    std::uint16_t surface_material(int color) const
    {
        return static_cast<std::uint16_t>(material(color) + m_options.surface_material_offset);
    }

    /// `@O(d)`: a sphere; cpfg's view volume takes the 8 corners of its cube.
    void draw_sphere(std::span<const float> p)
    {
        double r = std::abs(0.5 * diameter(p));  // cpfg draws -d as d
        if (!m_options.bounds_only) {
            Spheres& spheres = m_scene.geometry.spheres;
            spheres.centres.push_back(key(m_turtle.position, static_cast<float>(r)));
            spheres.material.push_back(material(m_turtle.color));
            spheres.texture.push_back(no_texture);  // cpfg maps no texture on spheres
        }
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
        if (!m_options.bounds_only) {
            Discs& discs = m_scene.geometry.discs;
            discs.centres.push_back(key(m_turtle.position, static_cast<float>(r)));
            discs.normals.push_back({static_cast<float>(normal.x), static_cast<float>(normal.y),
                                     static_cast<float>(normal.z)});
            discs.material.push_back(material(m_turtle.color));
            discs.back_material.push_back(material(m_turtle.back_color));
        }
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
        m_polygon_starts.push_back(m_module_index);
    }

    void add_polygon_vertex()
    {
        if (m_polygons.back().size() >= max_polygon_vertices)
            throw Error("a polygon with more than " + std::to_string(max_polygon_vertices) +
                                       " vertices");
        m_polygons.back().push_back({m_turtle.position, m_turtle.heading, m_turtle.left,
                                     m_turtle.color, m_turtle.back_color, m_turtle.texture,
                                     m_polygon_starts.back()});
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
        m_polygon_starts.pop_back();
    }

    /// Materials and texture are the first vertex's (as cpfg's rayshade output
    /// takes them); texture coordinates come from its frame (report 5.3): u along
    /// R = -L, v along H, each scaled to [0, 1] over the polygon.
    void emit_polygon(const std::vector<PolygonCorner>& corners)
    {
        if (m_options.bounds_only)
            return;  // its corners are turtle positions, in the bounds already
        // a polygon is its `{`'s organ, not the `}`'s that draws it
        if (m_provenance && !corners.empty()) {
            attribute(m_module_index);
            emit_polygon_now(corners);
            attribute(corners.front().opened_at);
            return;
        }
        emit_polygon_now(corners);
    }

    void emit_polygon_now(const std::vector<PolygonCorner>& corners)
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
        if (m_polygon_outlines)
            mesh.hidden_edges.resize(mesh.triangles.size(), 0);
        for (const auto& t : triangles) {
            mesh.triangles.push_back({base + t[0], base + t[1], base + t[2]});
            mesh.material.push_back(material(corners[0].color));
            mesh.back_material.push_back(material(corners[0].back_color));
            mesh.texture.push_back(static_cast<std::int16_t>(corners[0].texture));
            if (m_polygon_outlines)
                mesh.hidden_edges.push_back(inner_edges(t, outline));
        }
    }

    /// cpfg draws a polygon as one GL_POLYGON, whose wireframe is its outline. A
    /// triangle's edge is on the outline when the outline runs from one end to the
    /// other (either way round) through repeated or collinear corners only, which the
    /// triangulation skips; otherwise it is an inner edge.
    static std::uint8_t inner_edges(const std::array<std::uint32_t, 3>& t, const std::vector<Vec3>& outline)
    {
        const std::size_t n = outline.size();
        auto along_outline = [&](std::size_t from, std::size_t to) {
            const Vec3 a = outline[from], d = outline[to] - a;
            const double dd = dot(d, d);
            for (std::size_t i = (from + 1) % n; i != to; i = (i + 1) % n) {
                Vec3 p = outline[i] - a;
                double s = dd > 0 ? dot(p, d) / dd : 0;
                if (s < -1e-9 || s > 1 + 1e-9 || geom::length(p - d * s) > 1e-6 * std::max(1.0, std::sqrt(dd)))
                    return false;
            }
            return true;
        };
        std::uint8_t bits = 0;
        for (int k = 0; k < 3; ++k) {
            std::size_t a = t[static_cast<std::size_t>(k)], b = t[static_cast<std::size_t>((k + 1) % 3)];
            if (!along_outline(a, b) && !along_outline(b, a))
                bits = static_cast<std::uint8_t>(bits | (1u << k));
        }
        return bits;
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

    /// `@L(text [, values...])`: a label at the turtle in its colour.
    void add_label(std::span<const float> p)
    {
        Label label;
        label.position = m_turtle.position;
        label.material = material(m_turtle.color);
        if (std::optional<std::string> text = label_text(p, m_options.strings))
            label.text = std::move(*text);
        else if (!m_options.strings.empty() || !p.empty())
            warn_once(m_warned_label, "@L without a known string: label text left empty");
        // The labels' text and entries count against the memory budget before they are
        // stored: a string of @L modules with wide formats would otherwise grow without
        // bound between two checks of the geometry (every memory_check_interval modules).
        std::vector<Label>& labels = m_scene.labels;
        std::size_t capacity = labels.size() < labels.capacity()
                                   ? labels.capacity()
                                   : std::max<std::size_t>(1, 2 * labels.capacity());
        std::uint64_t& text_bytes = m_root->m_label_text_bytes;
        text_bytes += label.text.size();
        std::uint64_t bytes = text_bytes + std::uint64_t(capacity) * sizeof(Label);
        if (bytes > m_options.max_memory_bytes)
            throw Error("the @L labels need " + byte_size_text(bytes) + " for " +
                        std::to_string(labels.size() + 1) + " labels at module " +
                        std::to_string(m_module_index) + " of the string, more than the " +
                        "memory budget of " + byte_size_text(m_options.max_memory_bytes) +
                        " (--max-memory); use fewer or shorter labels or raise --max-memory");
        labels.push_back(std::move(label));
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
        if (m_taper_open && tapers() && !m_options.bounds_only)
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
        m_turtle.remember_frame();  // F and G: the reference for twist-free adjustments
        m_taper_open = true;
        if (m_options.bounds_only)
            return;  // the segment's ends are turtle positions, in the bounds at the nodes
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
        m_chain_open = true;
    }

    static std::array<float, 4> key(const Vec3& p, float radius)
    {
        return {static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z), radius};
    }

    static constexpr std::size_t max_open_polygons = 100'000;
    static constexpr std::size_t max_polygon_vertices = 10'000'000;
    static constexpr std::size_t max_sub_lsystem_depth = 100'000;

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
    std::vector<TurtleAtModule>* m_communication = nullptr;
    /// collect_polygons: the ranges, the next to begin, and those begun, with the
    /// scene's arrays when they began
    std::vector<std::vector<GlsPolygon>>* m_capture = nullptr;
    std::span<const ModuleRange> m_capture_ranges;
    std::size_t m_capture_next = 0;
    std::vector<std::pair<std::size_t, GeometryMark>> m_captures_open;

    void begin_captures()
    {
        while (m_capture_next < m_capture_ranges.size() &&
               m_capture_ranges[m_capture_next].begin <= m_module_index) {
            if (m_capture_ranges[m_capture_next].begin == m_module_index)
                m_captures_open.emplace_back(m_capture_next, geometry_mark(m_scene));
            ++m_capture_next;
        }
    }

    void end_captures()
    {
        std::erase_if(m_captures_open, [&](const auto& open) {
            if (m_capture_ranges[open.first].end > m_module_index)
                return false;
            append_polygons_since(m_scene, open.second, (*m_capture)[open.first]);
            return true;
        });
    }
    std::vector<Turtle>* m_fresh_turtles = nullptr;           ///< the fragment pass's
    std::vector<std::uint32_t>* m_fragment_starts = nullptr;  ///< ... and their modules
    std::size_t m_fresh_limit = 0;
    bool m_warned_fragment = false;
    std::vector<SurfaceDef> m_surfaces;                  ///< their prototypes moved out
    struct SurfacePrototypes {
        std::uint32_t per_patch;  ///< uvs per patch (cpfg's default)
        int per_surface;          ///< uvs over the surface, for `S:` textures; -1: not made
    };
    std::vector<SurfacePrototypes> m_surface_prototypes;  ///< per surface
    LsystemPatches m_patches;
    std::shared_ptr<const SymbolTables> m_tables;
    std::unique_ptr<ObjectInstancer> m_objects;  ///< `-o>` objects (root, with object hooks)
    bool m_advancing = false;              ///< inside advance(): geometry is cut afterwards
    std::size_t m_polygon_floor = 0;       ///< polygons below this index began before the object
    std::vector<std::vector<PolygonCorner>> m_outer_polygons;
    std::size_t m_module_index = 0;
    std::uint64_t m_label_text_bytes = 0;  ///< of every label this one's root stored
    std::vector<std::size_t> m_polygon_starts;  ///< per open polygon, its `{`'s index
    bool m_provenance = false;  ///< the root records each primitive's module
    std::vector<int> m_name_of_symbol;  ///< provenance: ModuleTable::names index, or -1

    /// Provenance: the primitives and instances made since the last call are module
    /// `turtle_index`'s (through the origins, in the derived string); entries of ones cut
    /// away since (an object's expansion, a generalized cylinder) go with them.
    void attribute(std::size_t turtle_index)
    {
        const std::uint32_t module = m_options.origins.empty()
                                         ? static_cast<std::uint32_t>(turtle_index)
                                         : m_options.origins[turtle_index];
        Geometry& g = m_scene.geometry;
        bool grew = sync(g.lines.module, g.lines.segment_count(), module);
        grew |= sync(g.curves.module, g.curves.segment_count(), module);
        grew |= sync(g.spheres.module, g.spheres.size(), module);
        grew |= sync(g.discs.module, g.discs.size(), module);
        grew |= sync(g.mesh.module, g.mesh.size(), module);
        for (std::size_t i = m_instances_attributed; i < m_scene.instances.size(); ++i, grew = true)
            m_scene.instances[i].module = module;
        m_instances_attributed = m_scene.instances.size();
        if (grew)
            record(module, turtle_index);
    }

    static bool sync(std::vector<std::uint32_t>& v, std::size_t n, std::uint32_t module)
    {
        const bool grew = v.size() < n;
        v.resize(n, module);
        return grew;
    }

    void record(std::uint32_t module, std::size_t turtle_index)
    {
        ModuleTable& t = m_scene.geometry.modules;
        // string order, but a polygon's `{` is recorded when its `}` draws it
        auto at = t.records.end();
        if (!t.records.empty() && t.records.back().index >= module) {
            at = std::lower_bound(t.records.begin(), t.records.end(), module,
                                  [](const ModuleRecord& r, std::uint32_t i) { return r.index < i; });
            if (at != t.records.end() && at->index == module)
                return;
        }
        const lsys::SymbolId symbol = m_options.derived && module < m_options.derived->size()
                                          ? m_options.derived->symbol(module)
                                          : m_string->symbol(turtle_index);
        if (symbol >= m_name_of_symbol.size())
            m_name_of_symbol.resize(symbol + 1, -1);
        if (m_name_of_symbol[symbol] < 0) {
            m_name_of_symbol[symbol] = static_cast<int>(t.names.size());
            t.names.emplace_back(m_tables->symbols->name(symbol));
        }
        const std::uint16_t age = module < m_options.ages.size() ? m_options.ages[module] : unknown_age;
        if (m_options.branch_orders) {
            // the brackets open where the module's successor began, not the successor's own
            const std::size_t open = module == m_depth_module ? m_module_depth : m_stack.size();
            const std::size_t depth = std::min<std::size_t>(open, ModuleTable::no_branch_order - 1);
            t.orders.insert(t.orders.begin() + (at - t.records.begin()), static_cast<std::uint16_t>(depth));
        }
        if (!m_options.births.empty())
            t.births.insert(t.births.begin() + (at - t.records.begin()),
                            module < m_options.births.size() ? m_options.births[module] : module);
        t.records.insert(at, {module, static_cast<std::uint16_t>(m_name_of_symbol[symbol]), age});
    }
    /// Branch orders: the turtle's open brackets before the first turtle module of
    /// derived module m_depth_module (a homomorphism may open brackets of its own).
    void note_module_depth()
    {
        const std::uint32_t module = m_options.origins.empty()
                                         ? static_cast<std::uint32_t>(m_module_index)
                                         : m_options.origins[m_module_index];
        if (module != m_depth_module) {
            m_depth_module = module;
            m_module_depth = m_stack.size();
        }
    }
    std::uint32_t m_depth_module = no_module;
    std::size_t m_module_depth = 0;
    std::size_t m_instances_attributed = 0;
    const lsys::ModuleString* m_string = nullptr;  ///< the string run() interprets
    bool m_warned_system = false, m_warned_include = false, m_warned_grid = false;
    bool m_warned_scale = false, m_warned_unmatched_polygon = false, m_warned_movement = false;
    bool m_warned_unmatched_sub = false, m_warned_label = false;
    bool m_warned_patch = false, m_warned_texture = false, m_warned_color = false;
    std::string m_warned_surface_letters;  ///< undefined `~x` letters already reported
    bool m_chain_open = false;  ///< the last key is at the turtle and may be shared
    bool m_taper_open = false;  ///< the last segment's top width may still change
    bool m_warned_unbalanced = false;
    bool m_past_cut = true;  ///< `interpretation past %:`
    /// `render mode: wireframe`: polygons mark their inner edges (TriangleMesh::hidden_edges).
    bool m_polygon_outlines = false;
    int m_cut_depth = -1;    ///< skipping a cut branch: brackets opened since; -1: not
};

}  // namespace

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

std::vector<std::uint32_t> save_fragment_turtles(const lsys::ModuleString& string,
                                                 const lsys::SymbolTable& symbols,
                                                 const ViewFile& view, std::vector<Turtle>& saved,
                                                 std::uint32_t first, std::uint32_t limit)
{
    saved.resize(std::min<std::size_t>(first, saved.size()));
    InterpretOptions options;
    options.bounds_only = true;  // only the turtle matters
    options.fragment_turtles = saved;
    std::vector<Turtle> fresh;
    std::vector<std::uint32_t> starts;
    Interpreter interpreter(view, options);
    interpreter.collect_fragments(&fresh, &starts, limit > first ? limit - first : 0);
    interpreter.run(string, symbols);
    saved.insert(saved.end(), fresh.begin(), fresh.end());
    return starts;
}

std::vector<QueryAnswer> collect_query_answers(const lsys::ModuleString& string,
                                               const lsys::SymbolTable& symbols,
                                               const ViewFile& view)
{
    std::vector<QueryAnswer> answers;
    InterpretOptions options;
    options.provenance = false;
    Interpreter interpreter(view, options);
    interpreter.collect_queries(&answers);
    interpreter.run(string, symbols);
    return answers;
}

std::vector<TurtleAtModule> collect_communication_turtles(const lsys::ModuleString& string,
                                                          const lsys::SymbolTable& symbols,
                                                          const ViewFile& view,
                                                          std::span<const ModuleRange> ranges,
                                                          std::vector<std::vector<GlsPolygon>>* polygons)
{
    std::vector<TurtleAtModule> turtles;
    InterpretOptions options;
    options.provenance = false;
    Interpreter interpreter(view, options);
    interpreter.collect_communication(&turtles);
    if (polygons)
        interpreter.collect_polygons(ranges, polygons);
    interpreter.run(string, symbols);
    return turtles;
}

}  // namespace cambium::geom
