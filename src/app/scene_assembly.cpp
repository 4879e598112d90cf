// SPDX-License-Identifier: Apache-2.0
// From a scene file to one geom::Scene.
//
// Plants are grouped by (model folder, command line, seed): one group loads its model
// once and derives it once, to its largest step count, interpreting the string at each
// of its step counts on the way; groups run in parallel (a Model keeps
// the last derivation's globals for its interpretation, so one Model is never shared
// between threads). Each plant variant becomes a prototype; each placement an
// instance. Embree (as Debian builds it) has one instance level, so the organs a plant
// instances itself (objects, surfaces) are either composed with every placement into
// top-level instances or drawn into the plant's prototype (OrganPlacement).
#include "app/scene_assembly.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <map>
#include <mutex>
#include <numbers>
#include <thread>
#include <sstream>

#include <tbb/parallel_for.h>

#include "app/pipeline.h"
#include "app/shared_environments.h"
#include "base/diagnostics.h"
#include "base/limits.h"
#include "base/subprocess.h"
#include "geom/background_scene.h"
#include "geom/placed_geometry.h"
#include "geom/primitives.h"
#include "geom/scene_limits.h"
#include "render/framing.h"
#include "render/render.h"

namespace cambium::app {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start)
{
    return std::chrono::duration<double>(Clock::now() - start).count();
}

/// Plants that share a model, its command line and seed: loaded once.
struct Group {
    const ScenePlant* first = nullptr;          ///< the entry that named it first
    const EnvironmentSeat* seat = nullptr;      ///< an open plant's shared environment
    std::vector<std::optional<int>> steps;      ///< distinct, in order of appearance
    std::vector<geom::Scene> variants;          ///< per step, interpreted
};

std::string group_key(const ScenePlant& p)
{
    // The command's words, so spacing does not make two groups of one model.
    std::string key = p.folder.lexically_normal().string() + '\n';
    std::istringstream words(p.command);
    for (std::string w; words >> w;)
        key += w + ' ';
    return key + '\n' + (p.seed ? std::to_string(*p.seed) : "-");
}

/// The options a plant of `group` is derived and interpreted with: the command line's
/// limits and permissions, the model's files.
Options plant_options(const Options& options, const ScenePlant& plant)
{
    Options o = options;
    o.lsystem = plant.model.lsystem;
    o.view = plant.model.view;
    o.colour_files = plant.model.colour_files;
    o.colour_block = plant.model.colour_block;
    o.environment_file = plant.model.environment_file;
    o.lsystem_seed = plant.seed;
    o.homomorphism_in_string = false;
    o.string_text.reset();
    o.string_binary.reset();
    o.view_volume.reset();
    o.rayshade.reset();
    o.postscript.reset();
    o.inventor.reset();
    o.verbosity = Verbosity::normal;
    return o;
}

struct Timing {
    std::atomic<std::int64_t> load_us{0}, derive_us{0}, interpret_us{0};
    std::atomic<std::size_t> models{0}, derivations{0}, variants{0};
    std::atomic<std::uint64_t> steps{0};
    void add(std::atomic<std::int64_t>& to, Clock::time_point start)
    {
        to += std::chrono::duration_cast<std::chrono::microseconds>(Clock::now() - start).count();
    }
};

/// The interpreted variants every group holds until the scene is combined, counted
/// together against the memory budget: each derivation checks its own string, but a
/// thousand variants that each fit can still exhaust memory side by side.
class HeldVariants {
public:
    explicit HeldVariants(std::uint64_t max_bytes) : m_max_bytes(max_bytes) {}
    void hold(const geom::Scene& variant)
    {
        std::uint64_t now = m_bytes += geom::scene_buffer_bytes(variant);
        std::uint64_t count = ++m_count;
        if (now > m_max_bytes)
            throw Error("the plants interpreted so far (" + std::to_string(count) + " variants) hold " +
                        byte_size_text(now) + ", more than the memory budget of " +
                        byte_size_text(m_max_bytes) + " (--max-memory)");
    }

private:
    const std::uint64_t m_max_bytes;
    std::atomic<std::uint64_t> m_bytes{0};
    std::atomic<std::uint64_t> m_count{0};
};

void derive_group(Group& g, const SceneFile& file, const Options& options, Timing& t, HeldVariants& held)
{
    // A seated plant leaves its shared environment once derived, or when it fails, so
    // that the others' steps never wait for it.
    struct Leave {
        const EnvironmentSeat* seat;
        void now() const
        {
            if (seat)
                seat->environment->leave(seat->plant);
        }
        ~Leave() { now(); }
    } leave{g.seat};
    try {
        Options o = plant_options(options, *g.first);
        auto start = Clock::now();
        Model model = load_model(o, g.seat);
        t.add(t.load_us, start);
        ++t.models;
        g.variants.resize(g.steps.size());
        std::int64_t interpret_us = 0;
        start = Clock::now();
        VariantRuns runs = derive_variants(model, g.steps, [&](std::size_t k, const lsys::ModuleString& s) {
            leave.now();  // a seated plant has one variant
            auto begin = Clock::now();
            StringOrigins provenance;  // organs named by the derived string's modules
            g.variants[k] = interpret_with_provenance(model, s, o, provenance);
            held.hold(g.variants[k]);
            interpret_us += std::chrono::duration_cast<std::chrono::microseconds>(Clock::now() - begin).count();
        });
        t.derive_us += std::chrono::duration_cast<std::chrono::microseconds>(Clock::now() - start).count() -
                       interpret_us;
        t.interpret_us += interpret_us;
        t.derivations += runs.runs;
        t.steps += runs.steps;
        t.variants += g.steps.size();
    } catch (const Interrupted&) {
        throw;
    } catch (const Error& e) {
        if (g.seat)
            g.seat->environment->abandon("another plant sharing this environment failed");
        throw Error(file.file.string() + ": " + g.first->path + " (" + g.first->command +
                    "): " + nested_message(e));
    }
}

/// Derives the seated groups together, each in a thread of its own: they meet at every
/// step of their shared environments, so none may wait for a thread pool's free worker.
/// The first failure is thrown (the others it caused are not).
void derive_seated_groups(std::vector<Group>& groups, const std::vector<std::size_t>& seated,
                          const SceneFile& file, const Options& options, Timing& timing,
                          HeldVariants& held)
{
    std::vector<std::exception_ptr> errors(seated.size());
    std::atomic<int> first{-1};
    {
        std::vector<std::jthread> threads;
        threads.reserve(seated.size());
        for (std::size_t k = 0; k < seated.size(); ++k)
            threads.emplace_back([&, k] {
                try {
                    derive_group(groups[seated[k]], file, options, timing, held);
                } catch (...) {
                    errors[k] = std::current_exception();
                    int none = -1;
                    first.compare_exchange_strong(none, static_cast<int>(k));
                }
            });
    }
    if (first >= 0)
        std::rethrow_exception(errors[static_cast<std::size_t>(first.load())]);
}

bool same_material(const geom::Material& x, const geom::Material& y)
{
    return x.ambient == y.ambient && x.diffuse == y.diffuse && x.emission == y.emission &&
           x.specular == y.specular && x.shininess == y.shininess &&
           x.transparency == y.transparency && x.translucency == y.translucency;
}

bool same_texture(const geom::TextureDef& x, const geom::TextureDef& y)
{
    return x.file == y.file && x.decal == y.decal && x.linear_filter == y.linear_filter &&
           x.mipmap == y.mipmap;
}

/// Tables appended to a combined table: (offset, size) each.
using Tables = std::vector<std::pair<std::size_t, std::size_t>>;

/// A plant variant ready to place: its prototype, its organs' instances in its own
/// frame, its bounds.
struct PlacedVariant {
    std::optional<std::uint32_t> prototype;    ///< none when it drew nothing
    std::vector<geom::Instance> organs;        ///< compose: placed with every placement
    geom::Geometry flat;                       ///< inline_plants: everything, organs drawn
    geom::Bounds3 bounds;
};

/// Builds the combined scene's tables (materials, textures, prototypes) from the
/// variants, one palette per distinct palette (plants keep their colours).
class Combiner {
public:
    Combiner(geom::Scene& out, const AssemblyOptions& how, const SceneFile& file)
        : m_out(out), m_how(how), m_file(file)
    {
    }

    /// `placements`: how many times the variant is placed (for the automatic choice).
    PlacedVariant add(geom::Scene& variant, const ScenePlant& plant, std::size_t placements)
    {
        std::uint16_t material_offset = palette_offset(variant.materials);
        std::int16_t texture_offset = texture_table_offset(variant.textures, plant);
        auto shift_instance = [&](geom::Instance inst) {
            if (inst.material != geom::inherit_material)
                inst.material = static_cast<std::uint16_t>(inst.material + material_offset);
            if (inst.back_material != geom::inherit_material)
                inst.back_material = static_cast<std::uint16_t>(inst.back_material + material_offset);
            if (inst.texture != geom::no_texture)
                inst.texture = static_cast<std::int16_t>(inst.texture + texture_offset);
            return inst;
        };
        for (geom::Prototype& p : variant.prototypes) {
            geom::offset_materials(p.geometry, material_offset);
            geom::offset_textures(p.geometry, texture_offset);
        }
        geom::offset_materials(variant.geometry, material_offset);
        geom::offset_textures(variant.geometry, texture_offset);

        PlacedVariant v;
        v.bounds = variant.bounds;
        bool flatten = m_how.inline_plants || m_how.organs == OrganPlacement::flatten ||
                       (m_how.organs == OrganPlacement::automatic &&
                        flattening_is_smaller(variant, placements));
        if (flatten) {
            for (const geom::Instance& i : variant.instances) {
                geom::Geometry organ = variant.prototypes.at(i.prototype).geometry;
                geom::place_geometry(organ, shift_instance(i));
                geom::append_geometry(variant.geometry, organ);
            }
        } else {
            std::vector<std::uint32_t> index(variant.prototypes.size());
            for (std::size_t k = 0; k < variant.prototypes.size(); ++k) {
                index[k] = static_cast<std::uint32_t>(m_out.prototypes.size());
                m_out.prototypes.push_back(std::move(variant.prototypes[k]));
            }
            for (const geom::Instance& i : variant.instances) {
                geom::Instance organ = shift_instance(i);
                organ.prototype = index.at(i.prototype);
                v.organs.push_back(organ);
            }
        }
        if (m_how.inline_plants) {
            v.flat = std::move(variant.geometry);
        } else if (!variant.geometry.empty()) {
            v.prototype = static_cast<std::uint32_t>(m_out.prototypes.size());
            m_out.prototypes.push_back({plant.path, std::move(variant.geometry)});
        }
        return v;
    }

    /// A `meshes` entry's OBJ: its materials and textures joined to the scene's tables,
    /// its surface one prototype (returned).
    std::uint32_t add_mesh(ObjModel& model, const SceneMesh& entry)
    {
        const std::uint16_t material_offset = palette_offset(model.materials);
        const std::int16_t texture_offset = static_cast<std::int16_t>(
            table_offset(m_out.textures, m_texture_tables, model.textures, same_texture, 32767,
                         "the plants name more than 32767 textures"));
        geom::Geometry g;
        g.mesh = std::move(model.mesh);
        geom::offset_materials(g, material_offset);
        geom::offset_textures(g, texture_offset);
        m_out.prototypes.push_back({entry.path, std::move(g)});
        return static_cast<std::uint32_t>(m_out.prototypes.size() - 1);
    }

private:
    /// Whether drawing the organs into the prototype takes less memory than placing
    /// them at the top level: a placed organ costs an instance (Embree's ~88 B, its BVH
    /// share and Cambium's 24 B: ~150 B), a drawn organ primitive about 100 B
    /// (/work/shared/FACTS.md: 52 to 169 B a primitive); drawn organs are paid once
    /// per variant, placed ones once per placement.
    static bool flattening_is_smaller(const geom::Scene& variant, std::size_t placements)
    {
        constexpr double instance_bytes = 150, primitive_bytes = 100;
        double drawn = 0;
        for (const geom::Instance& i : variant.instances) {
            drawn += double(primitive_count(variant.prototypes.at(i.prototype).geometry)) *
                     primitive_bytes;
        }
        double placed = double(variant.instances.size()) * double(placements) * instance_bytes;
        return drawn <= placed;
    }

    /// Where `table` starts in `all`: at an equal table added before (the variants of
    /// one model share their palette), else appended. `limit`: the most entries `all`
    /// may hold.
    template <typename T, typename Same>
    std::size_t table_offset(std::vector<T>& all, Tables& tables, const std::vector<T>& table,
                             Same same, std::size_t limit, const char* too_many)
    {
        for (const auto& [offset, size] : tables)
            if (size == table.size() &&
                std::equal(table.begin(), table.end(), all.begin() + long(offset), same))
                return offset;
        std::size_t offset = all.size();
        if (offset + table.size() > limit)
            throw Error(m_file.file.string() + ": plants: " + too_many);
        all.insert(all.end(), table.begin(), table.end());
        tables.emplace_back(offset, table.size());
        return offset;
    }

    /// The offset of `materials` in the combined table (inherit_material, 0xffff, is
    /// reserved).
    std::uint16_t palette_offset(const std::vector<geom::Material>& materials)
    {
        return static_cast<std::uint16_t>(table_offset(
            m_out.materials, m_palettes, materials, same_material, geom::inherit_material - 1,
            "the plants' palettes need more than 65534 materials together (about 250 "
            "distinct models or colour blocks)"));
    }

    /// The same for textures, whose files become absolute (relative to each model's
    /// view file, as cpfg reads them).
    std::int16_t texture_table_offset(std::vector<geom::TextureDef> textures, const ScenePlant& plant)
    {
        for (geom::TextureDef& t : textures)
            if (t.file.is_relative())
                t.file = fs::absolute(plant.model.view.parent_path() / t.file);
        return static_cast<std::int16_t>(table_offset(m_out.textures, m_texture_tables, textures,
                                                      same_texture, 32767,
                                                      "the plants name more than 32767 textures"));
    }

    geom::Scene& m_out;
    const AssemblyOptions& m_how;
    const SceneFile& m_file;
    Tables m_palettes, m_texture_tables;
};

geom::Bounds3 placed_bounds(const geom::Bounds3& b, const Transform& t)
{
    geom::Bounds3 out;
    if (b.empty())
        return out;
    for (int i = 0; i < 8; ++i) {
        double x = (i & 1) ? b.hi.x : b.lo.x, y = (i & 2) ? b.hi.y : b.lo.y,
               z = (i & 4) ? b.hi.z : b.lo.z;
        out.extend(geom::Affine3x4(t).apply(geom::Vec3{x, y, z}));
    }
    return out;
}

// ---- ground -------------------------------------------------------------------

void add_ground(geom::Scene& out, const SceneGround& ground, const SceneLimits& limits)
{
    geom::Material soil;
    soil.diffuse = ground.texture ? geom::Rgb{1, 1, 1} : ground.colour;
    soil.ambient = soil.diffuse;
    soil.specular = {0, 0, 0};
    if (out.materials.size() + 1 >= geom::inherit_material)
        throw Error("scene: no material left for the ground");
    auto material = static_cast<std::uint16_t>(out.materials.size());
    out.materials.push_back(soil);
    std::int16_t texture = geom::no_texture;
    if (ground.texture) {
        geom::TextureDef def;
        def.file = fs::absolute(*ground.texture);
        texture = static_cast<std::int16_t>(out.textures.size());
        out.textures.push_back(def);
    }

    GroundMesh mesh;
    if (ground.size) {
        float w = float((*ground.size)[0] / 2), d = float((*ground.size)[1] / 2);
        mesh.positions = {{-w, 0, -d}, {w, 0, -d}, {w, 0, d}, {-w, 0, d}};
        // counter-clockwise seen from above: the front faces +y
        mesh.triangles = {{0, 2, 1}, {0, 3, 2}};
    } else {
        mesh = read_obj_mesh(*ground.mesh, limits);
    }
    geom::Bounds3 extent;
    for (const geom::Float3& p : mesh.positions)
        extent.extend(geom::Vec3{p[0], p[1], p[2]});
    double size_x = std::max(extent.hi.x - extent.lo.x, 1e-9);
    double size_z = std::max(extent.hi.z - extent.lo.z, 1e-9);
    // Flat faces, each with its own corners: the face normal, uv planar over x and z.
    geom::TriangleMesh& m = out.geometry.mesh;
    m.texture.resize(m.triangles.size(), geom::no_texture);
    for (const auto& t : mesh.triangles) {
        geom::Vec3 c[3];
        for (int k = 0; k < 3; ++k) {
            const geom::Float3& p = mesh.positions[t[std::size_t(k)]];
            c[k] = {p[0], p[1], p[2]};
        }
        geom::Vec3 n = geom::normalize(geom::cross(c[1] - c[0], c[2] - c[0]));
        auto base = static_cast<std::uint32_t>(m.positions.size());
        for (const geom::Vec3& p : c) {
            m.positions.push_back({float(p.x), float(p.y), float(p.z)});
            m.normals.push_back({float(n.x), float(n.y), float(n.z)});
            m.uvs.push_back({float((p.x - extent.lo.x) / size_x * ground.texture_repeat),
                             float((p.z - extent.lo.z) / size_z * ground.texture_repeat)});
        }
        m.triangles.push_back({base, base + 1, base + 2});
        m.material.push_back(material);
        m.back_material.push_back(material);
        m.texture.push_back(texture);
    }
    out.bounds.extend(extent);
}

// ---- camera and lights ----------------------------------------------------------

/// The view's twist that turns cpfg's up (+y, projected) into `up`.
double twist_for(const geom::Vec3& forward, const geom::Vec3& up)
{
    geom::Vec3 y{0, 1, 0};
    if (std::abs(geom::dot(forward, y)) > 1 - 1e-12)
        return 0;  // straight up or down: cpfg's own choice stands
    geom::Vec3 right = geom::normalize(geom::cross(forward, y));
    geom::Vec3 up0 = geom::cross(right, forward);
    geom::Vec3 wanted = up - forward * geom::dot(up, forward);
    if (geom::length(wanted) < 1e-12)
        throw Error("scene: camera.up points along the view direction");
    wanted = geom::normalize(wanted);
    // positive twist turns up counter-clockwise about -forward (render::view_frame)
    double angle = std::atan2(geom::dot(geom::cross(up0, wanted), forward * -1.0),
                              geom::dot(up0, wanted));
    return angle * 180 / std::numbers::pi;
}

geom::View scene_view(const SceneFile& file, const geom::Bounds3& bounds)
{
    SceneCamera cam = file.camera.value_or(SceneCamera{});
    geom::View view;
    view.perspective = cam.perspective;
    view.viewing_angle_deg = cam.fov_deg;
    geom::Bounds3 b = bounds;
    if (b.empty())
        b.extend(geom::Vec3{0, 0, 0});
    geom::Vec3 centre = b.center();
    if (cam.eye && cam.look_at) {
        view.viewpoint = *cam.eye;
        view.reference_point = *cam.look_at;
    } else {
        // Framed from the front, a little above, unless the file says where.
        view.reference_point = cam.look_at.value_or(centre);
        geom::Vec3 from = cam.eye.value_or(view.reference_point + geom::Vec3{0, 0.5, 1});
        view.viewpoint = from;
        if (!cam.eye) {
            render::ViewOverrides fit;
            fit.fit = true;
            view = render::apply_overrides(view, fit, b);
        }
    }
    geom::Vec3 forward = geom::normalize(view.reference_point - view.viewpoint);
    view.twist_deg = twist_for(forward, cam.up);
    return view;
}

std::vector<geom::Light> scene_lights(const SceneFile& file)
{
    if (!file.lights.empty() || file.sky || file.environment)
        return file.lights;  // the sky's sun, or the map, lights the scene
    // A white sun from the front right, high: a daylight default.
    geom::Light sun;
    sun.kind = geom::Light::Kind::directional;
    sun.direction = geom::normalize(geom::Vec3{0.4, 1, 0.6});
    sun.ambient = {0, 0, 0};
    return {sun};
}

}  // namespace

namespace {

/// What placing every plant adds, counted before any is placed: each placement brings
/// its plant and every organ its view composes (-o> objects), or a copy of the whole
/// plant when inlined. The scene file bounded the placements alone; their product with
/// the organs is bounded here, by the instance limit and the memory budget.
template <typename Entries>
void check_placed_size(const SceneFile& file, const Entries& entries,
                       const std::vector<std::vector<PlacedVariant>>& placed,
                       const AssemblyOptions& how, const Options& options)
{
    constexpr double instance_bytes = 150, primitive_bytes = 100;  // as flattening_is_smaller
    double instances = 0, primitives = 0;
    for (std::size_t e = 0; e < file.plants.size(); ++e) {
        const auto& ref = entries[e];
        for (std::size_t i = 0; i < file.plants[e].placements.size(); ++i) {
            const PlacedVariant& v = placed[ref.group][ref.variants[i % ref.variants.size()]];
            if (how.inline_plants)
                primitives += double(primitive_count(v.flat));
            else
                instances += double(v.prototype ? 1 : 0) + double(v.organs.size());
        }
    }
    const std::size_t max_instances = SceneLimits{}.max_instances;
    const std::string what =
        file.file.string() + ": plants: the placements with their organs (-o>) ";
    if (instances > double(max_instances))
        throw Error(what + "make " + std::to_string(std::uint64_t(instances)) +
                    " instances, more than the limit of " + std::to_string(max_instances));
    double bytes = instances * instance_bytes + primitives * primitive_bytes;
    if (bytes > double(options.max_memory_bytes))
        throw Error(what + "need about " + byte_size_text(std::uint64_t(bytes)) +
                    ", more than the memory budget of " + byte_size_text(options.max_memory_bytes) +
                    " (--max-memory)");
}

}  // namespace

namespace {

geom::Scene assemble(const SceneFile& file, const std::vector<std::optional<EnvironmentSeat>>& seats,
                     const Options& options, const AssemblyOptions& how, AssemblyReport* report)
{
    auto start = Clock::now();
    // The meshes are read first: their errors come before any derivation.
    std::vector<ObjModel> meshes;
    for (const SceneMesh& m : file.meshes) {
        try {
            meshes.push_back(read_obj_model(m.file, file.file.parent_path().empty()
                                                        ? fs::path(".")
                                                        : file.file.parent_path(),
                                            options.allow_file_access, SceneLimits{}));
        } catch (const Error& e) {
            throw Error(file.file.string() + ": " + m.path + ".file: " + nested_message(e));
        }
    }
    // Group the entries and their steps: each distinct variant derived once.
    std::vector<Group> groups;
    std::map<std::string, std::size_t> group_of_key;
    struct EntryRef {
        std::size_t group;
        std::vector<std::size_t> variants;  ///< per entry step: index in the group
    };
    std::vector<EntryRef> entries;
    for (std::size_t k = 0; k < file.plants.size(); ++k) {
        const ScenePlant& p = file.plants[k];
        const EnvironmentSeat* seat = k < seats.size() && seats[k] ? &*seats[k] : nullptr;
        // a seated plant is a group of its own: its neighbours shape it
        const std::string key = group_key(p) + (seat ? "\nseat " + std::to_string(k) : "");
        auto [it, added] = group_of_key.emplace(key, groups.size());
        if (added)
            groups.push_back(Group{&p, seat, {}, {}});
        Group& g = groups[it->second];
        EntryRef e{it->second, {}};
        for (const std::optional<int>& s : p.steps) {
            auto found = std::find(g.steps.begin(), g.steps.end(), s);
            e.variants.push_back(static_cast<std::size_t>(found - g.steps.begin()));
            if (found == g.steps.end())
                g.steps.push_back(s);
        }
        entries.push_back(std::move(e));
    }

    Timing timing;
    HeldVariants held(options.max_memory_bytes);
    std::vector<std::size_t> closed, seated;
    for (std::size_t i = 0; i < groups.size(); ++i)
        (groups[i].seat ? seated : closed).push_back(i);
    tbb::parallel_for(std::size_t{0}, closed.size(), [&](std::size_t i) {
        derive_group(groups[closed[i]], file, options, timing, held);
    });
    derive_seated_groups(groups, seated, file, options, timing, held);

    geom::Scene out;
    out.materials.clear();
    Combiner combiner(out, how, file);
    // How many times each variant is placed: entry e's placement i gets its
    // (i mod steps)-th variant.
    std::vector<std::vector<std::size_t>> uses(groups.size());
    for (std::size_t e = 0; e < file.plants.size(); ++e) {
        std::vector<std::size_t>& u = uses[entries[e].group];
        u.resize(groups[entries[e].group].steps.size(), 0);
        const std::vector<std::size_t>& v = entries[e].variants;
        for (std::size_t i = 0; i < file.plants[e].placements.size(); ++i)
            ++u[v[i % v.size()]];
    }
    std::vector<std::vector<PlacedVariant>> placed(groups.size());
    bool pixel_lines = false;
    for (std::size_t gi = 0; gi < groups.size(); ++gi) {
        Group& g = groups[gi];
        for (geom::Scene& variant : g.variants) {
            if (gi == 0 && placed[0].empty()) {
                pixel_lines = variant.line_radius_in_pixels;
                out.shading = variant.shading;
                out.background = variant.background;
            } else if (variant.line_radius_in_pixels != pixel_lines) {
                throw Error(file.file.string() + ": " + g.first->path +
                            ": its view file's `line style: pixel` differs from " +
                            groups[0].first->path + "'s; one scene has one line style");
            }
            placed[gi].push_back(combiner.add(variant, *g.first, uses[gi][placed[gi].size()]));
            variant = geom::Scene{};  // its geometry moved; free the rest
        }
    }
    out.line_radius_in_pixels = pixel_lines;

    check_placed_size(file, entries, placed, how, options);
    AssemblyReport r;
    for (std::size_t e = 0; e < file.plants.size(); ++e) {
        const ScenePlant& plant = file.plants[e];
        const EntryRef& ref = entries[e];
        for (std::size_t i = 0; i < plant.placements.size(); ++i) {
            const PlacedVariant& v = placed[ref.group][ref.variants[i % ref.variants.size()]];
            const Transform& t = plant.placements[i];
            out.bounds.extend(placed_bounds(v.bounds, t));
            ++r.plant_instances;
            if (how.inline_plants) {
                geom::Geometry copy = v.flat;
                geom::Instance where;
                where.transform = t;
                geom::place_geometry(copy, where);
                geom::append_geometry(out.geometry, copy);
                continue;
            }
            const auto placement = static_cast<std::uint32_t>(r.plant_instances - 1);
            if (v.prototype) {
                geom::Instance plant_instance;
                plant_instance.prototype = *v.prototype;
                plant_instance.transform = t;
                plant_instance.plant = placement;
                out.instances.push_back(plant_instance);
            }
            for (geom::Instance organ : v.organs) {
                organ.transform = compose(t, organ.transform);
                organ.plant = placement;
                out.instances.push_back(organ);
                ++r.organ_instances;
            }
        }
    }
    for (std::size_t k = 0; k < file.meshes.size(); ++k) {
        geom::Bounds3 bounds;
        for (const geom::Float3& p : meshes[k].mesh.positions)
            bounds.extend(geom::Vec3{p[0], p[1], p[2]});
        const std::uint32_t prototype = combiner.add_mesh(meshes[k], file.meshes[k]);
        for (const Transform& t : file.meshes[k].placements) {
            out.bounds.extend(placed_bounds(bounds, t));
            geom::Instance placed;
            placed.prototype = prototype;
            placed.transform = t;
            placed.plant = static_cast<std::uint32_t>(r.plant_instances++);
            out.instances.push_back(placed);
        }
        meshes[k] = ObjModel{};
    }
    if (file.ground)
        add_ground(out, *file.ground, SceneLimits{});
    out.view = scene_view(file, out.bounds);
    out.lights = scene_lights(file);
    geom::fit_scene_buffers(out);  // Embree reads the meshes in place; no growth slack

    r.models_loaded = timing.models;
    r.derivations = timing.derivations;
    r.variants = timing.variants;
    r.derivation_steps = timing.steps;
    r.load_s = double(timing.load_us) * 1e-6;
    r.derive_s = double(timing.derive_us) * 1e-6;
    r.interpret_s = double(timing.interpret_us) * 1e-6;
    r.wall_s = seconds_since(start);
    if (report)
        *report = r;
    return out;
}

}  // namespace

VariantRuns derive_variants(const Model& model, const std::vector<std::optional<int>>& steps,
                            const std::function<void(std::size_t, const lsys::ModuleString&)>& each)
{
    // One run derives to the largest step count and hands out the string at each smaller
    // one on the way, as a derivation that stops there would leave it: the End block
    // then runs on a copy of the globals (which the homomorphism reads) and the run goes
    // on from before it. An End block that uses files cannot run on a copy: then each
    // step count is derived from the axiom.
    const bool one_run = !model.lsystem.end_block_uses_files();
    VariantRuns done;
    std::optional<lsys::Derivation> run(model.lsystem.start());
    ++done.runs;
    // fewest steps first; no step count: the derivation length the Start block leaves
    std::vector<std::pair<int, std::size_t>> order;
    for (std::size_t k = 0; k < steps.size(); ++k)
        order.emplace_back(steps[k].value_or(run->derivation_length()), k);
    std::stable_sort(order.begin(), order.end());
    for (const auto& [n, k] : order) {
        if (!run) {
            run.emplace(model.lsystem.start());
            ++done.runs;
        }
        const int before = run->steps_done();
        run->advance(n - before);
        done.steps += std::uint64_t(run->steps_done() - before);
        // as LSystem::derive: a stop() before the last step skips the End block, unless
        // its argument is other than 1
        const bool stopped_early = run->stopped() && run->steps_done() < n;
        if (!stopped_early || run->stop_runs_end()) {
            if (one_run && n < order.back().first)
                run->finish_on_copy();
            else
                run->finish();
        }
        run->release_buffers();
        each(k, run->string());
        if (!one_run)
            run.reset();
    }
    return done;
}

geom::Scene assemble_scene(const SceneFile& file, const Options& options,
                           const AssemblyOptions& how, AssemblyReport* report)
{
    SeatedPlants seated = seat_open_plants(file, options);
    if (!seated.any)
        return assemble(file, {}, options, how, report);
    SceneFile split = file;
    split.plants = std::move(seated.plants);
    return assemble(split, seated.seats, options, how, report);
}

void apply_scene_settings(const SceneFile& file, Options& o)
{
    auto unless = [&](const char* option, auto& field, const auto& value) {
        if (value && !o.was_given(option))
            field = *value;
    };
    if (file.camera && !o.was_given("-w")) {
        if (file.camera->width)
            o.width = *file.camera->width;
        if (file.camera->height)
            o.height = *file.camera->height;
        if (std::int64_t(o.width) * o.height > render::max_image_pixels)
            throw Error(file.file.string() + ": camera: " + std::to_string(o.width) + " x " +
                        std::to_string(o.height) + " is more than 8192 x 8192 pixels");
    }
    const SceneRender& r = file.render;
    unless("--spp", o.samples_per_pixel, r.spp);
    unless("--max-depth", o.max_depth, r.max_depth);
    unless("--seed", o.seed, r.seed);
    unless("--noise-target", o.noise_target, r.noise_target);
    unless("--time-budget", o.time_budget_s, r.time_budget_s);
    unless("--exposure", o.exposure, r.exposure);
    unless("--ambient", o.ambient, r.ambient);
    unless("--filter", o.filter, r.filter);
    unless("--tonemap", o.shot.tonemap, r.tonemap);
    if (r.background && !o.was_given("--background"))
        o.shot.background = r.background;
    // As on the command line: a budget or a noise target decides when to stop.
    if (!r.spp && !o.was_given("--spp")) {
        if (o.time_budget_s > 0 && !o.was_given("--time-budget"))
            o.samples_per_pixel = 1 << 16;
        else if (o.noise_target > 0 && !o.was_given("--noise-target"))
            o.samples_per_pixel = 4096;
    }
    // The command line's --sky or --env replaces the file's sky or environment.
    bool lighting_given = o.was_given("--sky") || o.was_given("--env");
    if (file.sky && !lighting_given) {
        o.sky = true;
        if (file.sky->sun && !o.was_given("--sun"))
            o.sun_direction.assign(file.sky->sun->begin(), file.sky->sun->end());
        unless("--turbidity", o.turbidity, std::optional<float>(file.sky->turbidity));
    }
    if (file.environment && !lighting_given) {
        o.environment_map = file.environment->map;
        unless("--env-scale", o.environment_scale, std::optional<float>(file.environment->scale));
        unless("--env-rotate", o.environment_rotation,
               std::optional<float>(file.environment->rotate_deg));
    }
}

}  // namespace cambium::app
