// SPDX-License-Identifier: Apache-2.0
// Inputs the fuzz targets (fuzz/, docs/security.md) found to crash, each replayed as the
// target replays it and answered with the located error a user should see.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <string_view>

#include "base/diagnostics.h"
#include "lsys/lsystem.h"

namespace cambium {
namespace {

/// What the lsystem fuzz target does with a preprocessed .l text, up to derivation.
void derive_preprocessed(std::string_view text)
{
    lsys::LoadOptions options;
    options.max_modules = 2000;
    lsys::LSystem lsystem = lsys::LSystem::from_preprocessed(text, "plant.l", options);
    lsystem.derive(std::min(lsystem.derivation_length(), 3));
}

/// The cambium::Error message `run` throws ("" when it throws none).
template <class Run>
std::string error_of(Run&& run)
{
    try {
        run();
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

// Float to int conversions of user values: `derivation length: 2^56`
// was converted to int unchecked (UBSan: "7.20576e+16 is outside the range of
// representable values of type 'int'", src/lsys/deriver.cpp Deriver::start).
TEST(FuzzRegression, DerivationLengthOutOfIntRange)
{
    std::string message = error_of([] {
        derive_preprocessed("Lsystem: 1\nderivation length: 2^56\nAxiom: F\nendlsystem\n");
    });
    EXPECT_NE(message.find("plant.l:2:"), std::string::npos) << message;
    EXPECT_NE(message.find("derivation length"), std::string::npos) << message;
}

}  // namespace
}  // namespace cambium
