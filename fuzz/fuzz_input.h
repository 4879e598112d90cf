// SPDX-License-Identifier: Apache-2.0
// What every fuzz target shares: the input as text, a bound on its size, and the rule
// that cambium::Error is the only acceptable way to refuse an input.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string_view>

#include "base/diagnostics.h"

namespace cambium::fuzz {

/// Largest input a target looks at. The readers accept far more (64 MiB); fuzzing
/// looks for crashes, and small inputs keep every execution fast.
inline constexpr std::size_t max_input_bytes = 64u << 10;

inline std::string_view text_of(const std::uint8_t* data, std::size_t size)
{
    return {reinterpret_cast<const char*>(data), size};
}

/// Runs `read` on an input. A cambium::Error (a located message for the user) is the
/// expected answer to bad input; any other exception escapes, and libFuzzer reports it
/// as a crash, because the user would see "error: vector::_M_range_check" or worse.
template <class Read>
int run(std::size_t size, Read&& read)
{
    if (size > max_input_bytes)
        return -1;  // not added to the corpus
    try {
        read();
    } catch (const cambium::Error&) {
    }
    return 0;
}

/// Writes the input to `name` in the current folder (scripts/fuzz.sh runs each target in
/// a scratch folder of its own) for readers that take a path, as the command's do.
inline std::filesystem::path write_input(const std::uint8_t* data, std::size_t size,
                                         const char* name)
{
    std::ofstream(name, std::ios::binary | std::ios::trunc)
        .write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    return name;
}

}  // namespace cambium::fuzz
