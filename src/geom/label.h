// SPDX-License-Identifier: Apache-2.0
// `@L` labels (manual: "@L("Label") prints the label in the drawing window at the current
// turtle location"): their text, printf-formatted from the module's parameters.
#pragma once

#include <optional>
#include <span>
#include <string>

#include "geom/scene.h"

namespace cambium::geom {

/// The text of `@L(text [, values...])`: the L-system string constant whose index is the
/// first parameter, with its printf conversions (%g %f %d %e...) replaced by the values
/// in turn. nullopt when the first parameter names no string of `strings`.
std::optional<std::string> label_text(std::span<const float> params, std::span<const std::string> strings);

/// Replaces each printf conversion of `format` with the next value (0 past the last);
/// anything that is not one conversion of a number (%s, %n, a conversion wider than 12
/// characters) is kept as text.
std::string format_label(const std::string& format, std::span<const float> values);

}  // namespace cambium::geom
