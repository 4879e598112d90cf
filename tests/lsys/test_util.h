// SPDX-License-Identifier: Apache-2.0
// Helpers shared by the lsys tests: derive inline sources to text, expect errors.
#pragma once

#include <gtest/gtest.h>

#include <string>

#include "base/diagnostics.h"
#include "lsys/lsystem.h"

namespace cambium::lsys::testing {

/// The text of `source` derived `steps` steps (default: its derivation length).
inline std::string derive_text(const std::string& source, std::optional<int> steps = std::nullopt)
{
    LSystem ls = LSystem::from_source(source, "test.l");
    return to_text(ls.derive(steps), ls.symbols());
}

/// The message of the cambium::Error that compiling `source` throws ("" if none).
inline std::string load_error(const std::string& source)
{
    try {
        LSystem::from_source(source, "test.l");
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

}  // namespace cambium::lsys::testing
