// SPDX-License-Identifier: Apache-2.0
// Resource limits that hold a model file's demands (docs/security.md): one memory budget
// shared by derivation, interpretation and texture loading.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace cambium {

/// Half of the machine's physical memory (4 GiB when it cannot be read): a hostile or
/// mistaken model stops with a message before the system swaps or its OOM killer ends
/// the process, and the other half stays for the BVH, the film and the system.
std::uint64_t default_max_memory_bytes();

/// The resource limits of one run (--max-memory).
struct Limits {
    /// What the derived strings (modules and parameters), the Scene's primitive arrays
    /// and one decoded texture may each take.
    std::uint64_t max_memory_bytes = default_max_memory_bytes();
};

/// "8G", "512M", "64k", "1.5G", "100000" (bytes; K M G T are powers of 1024, case and
/// a trailing "B" or "iB" ignored). nullopt when malformed, zero or above 2^60.
std::optional<std::uint64_t> parse_byte_size(std::string_view text);

/// A byte count for messages: "512 bytes", "3.2 MiB", "8.0 GiB".
std::string byte_size_text(std::uint64_t bytes);

}  // namespace cambium
