// SPDX-License-Identifier: Apache-2.0
// A model as cpfg loads it (view file, colours, functions, L-system), derived and
// interpreted. The `cambium` command and the corpus tests share this path to a Scene.
#pragma once

#include <array>
#include <filesystem>
#include <memory>

#include "app/command_line.h"
#include "env/environmental_step.h"
#include "env/shared_environment.h"
#include "geom/function.h"
#include "geom/palette.h"
#include "geom/rayshade_export.h"
#include "geom/scene.h"
#include "geom/turtle.h"
#include "geom/view_file.h"
#include "lsys/lsystem.h"

namespace cambium::app {

/// Everything read from a model's files, before derivation. The L-system's hooks
/// (func(), the query pass) refer to the view and functions held here by shared
/// pointers, so a Model may be moved.
struct Model {
    std::shared_ptr<const geom::ViewFile> view;
    geom::Palette palette;
    std::shared_ptr<const geom::FunctionSet> functions;
    lsys::LSystem lsystem;
    /// The turtles the last derivation saved at fragment starts `%(par)` (manual 5.1.9),
    /// by index, for drawing `%(par, index)`: derive() refills them.
    std::shared_ptr<std::vector<geom::Turtle>> fragment_turtles;
};

/// The folder every file a model names must lie in unless options.allow_file_access: the
/// .l file's, where cpfg runs (absolute, `..` and links resolved).
std::filesystem::path model_folder(const Options& options);

/// The view file, its texture images confined to the model's folder (the .l file's, where
/// cpfg runs) and below, as the L-system's own files are (docs/security.md): a texture
/// elsewhere, through `..`, an absolute path or a link, is an error naming the view file,
/// unless options.allow_file_access. Relative names are the view file's folder's.
std::shared_ptr<const geom::ViewFile> read_view(const Options& options);

/// The environment a model's `.e` file (`spec`, read from options.environment_file)
/// names, for this model alone: a built-in, or an external program when the options
/// allow it; a line says which unless quiet. Throws cambium::Error.
env::Connection model_environment(const Options& options, const env::CommSpec& spec);

/// A plant's seat at an environment shared with other plants (a scene file's field of
/// open L-systems, docs/environment.md): its number there and where it stands.
struct EnvironmentSeat {
    std::shared_ptr<env::SharedEnvironment> environment;
    std::size_t plant = 0;
    std::array<float, 12> placement{};
};

/// Reads the colour files, the view file, its functions and then the L-system, in that
/// order (a function set defines names for the L-system's preprocessor). Throws
/// cambium::Error naming file, line and column. With a seat, the `-e` file's environment
/// is the shared one (each derivation run takes the seat: derive such a model once).
Model load_model(const Options& options, const EnvironmentSeat* seat = nullptr);

/// The string after the derivation length (or --steps), decomposition included: what
/// cpfg's -str writes (homomorphism_in_string: after the homomorphism, as -homo).
lsys::ModuleString derive(const Model& model, const Options& options);

/// The turtle's interpretation of a derived string (the homomorphism applied first),
/// with the materials of the selected colour block, the view file's translucency
/// settings and its background scene.
geom::Scene interpret(const Model& model, const lsys::ModuleString& derived,
                      const Options& options);

/// The two halves of interpret(): the string the turtle reads (homomorphism applied
/// with the globals of the last derivation; instanceable objects kept whole) ...
lsys::ModuleString turtle_string(const Model& model, const lsys::ModuleString& derived,
                                 const Options& options);
/// Whether turtle_string() would return the derived string unchanged: no homomorphism
/// production and no split `@` command (nor, without --homo in the string, any object to
/// keep whole). The caller then interprets the derived string itself and saves a copy of
/// it (two full copies of a 23 M-module string cost a fifth of the tree's time to
/// first pixel, build/benchmarks/render).
bool turtle_reads_derived_string(const Model& model, const Options& options);
/// Where the turtle string's modules came from (provenance, docs/architecture.md).
struct StringOrigins {
    const lsys::ModuleString* derived = nullptr;  ///< the derived string
    std::vector<std::uint32_t> origins;  ///< per turtle-string module, its index in *derived
    std::vector<std::uint16_t> ages;     ///< per derived module (empty: unknown)
    /// Per derived module, its index in the string where it appeared (an animation's
    /// organ masks: ModuleTable::births); empty: not recorded.
    std::vector<std::uint32_t> births;
};
/// turtle_string(), its modules' origins in `derived` written to `origins`.
lsys::ModuleString turtle_string(const Model& model, const lsys::ModuleString& derived,
                                 const Options& options, std::vector<std::uint32_t>& origins);
/// ... and its interpretation into a Scene (its primitives' modules through `origins`).
geom::Scene interpret_turtle_string(const Model& model, const lsys::ModuleString& string,
                                    const Options& options, const StringOrigins* origins = nullptr);

/// derive(), with each derived module's age in `ages` when `with_ages` and the string is
/// not asked for with its homomorphism applied (-homo has no ages to give): the lineage
/// costs 4 bytes a module while deriving, so only what reports ages asks for them.
lsys::ModuleString derive(const Model& model, const Options& options, bool with_ages,
                          std::vector<std::uint16_t>& ages);
/// interpret() with every primitive's module: through the turtle string's origins in
/// `derived` when a homomorphism rewrites it, directly otherwise. `provenance.ages` as
/// derive() gave them; `provenance` points into `derived` until both are dropped.
geom::Scene interpret_with_provenance(const Model& model, const lsys::ModuleString& derived,
                                      const Options& options, StringOrigins& provenance);

/// What -vv writes: the view volume of a derived string (the view file's `box:` wins, as
/// in cpfg, unless not `box_wins`). The turtle walks the string without storing geometry, so a
/// -vv without an image costs the walk alone; the bounds equal interpret()'s.
geom::Bounds3 view_volume(const Model& model, const lsys::ModuleString& derived,
                          const Options& options, bool box_wins = true);

/// -ray FILE's settings: the main object named by the file (as cpfg names it), colormap or
/// material surfaces by the command's colour files, framed for its image size, and the
/// view file's `rayshade scale:` and the colour files' transparencies (none without a
/// model: a scene file's field).
geom::RayshadeOptions rayshade_options(const Options& options, const std::filesystem::path& file,
                                       const Model* model);

}  // namespace cambium::app
