// SPDX-License-Identifier: Apache-2.0
// A model as cpfg loads it (view file, colours, functions, L-system), derived and
// interpreted. The `cambium` command and the corpus tests share this path to a Scene.
#pragma once

#include <memory>

#include "app/command_line.h"
#include "geom/function.h"
#include "geom/palette.h"
#include "geom/scene.h"
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
};

/// The view file, its texture images confined to the model's folder (the .l file's, where
/// cpfg runs) and below, as the L-system's own files are (docs/security.md): a texture
/// elsewhere, through `..`, an absolute path or a link, is an error naming the view file,
/// unless options.allow_file_access. Relative names are the view file's folder's.
std::shared_ptr<const geom::ViewFile> read_view(const Options& options);

/// Reads the colour files, the view file, its functions and then the L-system, in that
/// order (a function set defines names for the L-system's preprocessor). Throws
/// cambium::Error naming file, line and column.
Model load_model(const Options& options);

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
/// ... and its interpretation into a Scene.
geom::Scene interpret_turtle_string(const Model& model, const lsys::ModuleString& string,
                                    const Options& options);

}  // namespace cambium::app
