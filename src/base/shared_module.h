// SPDX-License-Identifier: Apache-2.0
// Loading Cambium's optional shared modules with dlopen (libcambium_mpi.so for --mpi,
// libcambium_imageio.so for image files), so that a run loads a heavy library's
// dependency tree only when it needs it.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace cambium {

/// Where module `file_name` may be, in order: beside the executable (the build tree's
/// src/app), the install's library folder relative to the executable's bin folder, for
/// code loaded as a shared object (the Python module in P/lib/python3.X/dist-packages)
/// the folder two levels above it, the configured install library folder, and the build tree's module folder (for tests and
/// benchmarks that live elsewhere in the build tree).
std::vector<std::filesystem::path> module_candidates(const std::string& file_name);

/// A loaded module; never unloaded (its code may still be on the stack at exit).
struct SharedModule {
    void* handle = nullptr;
    std::filesystem::path file;

    /// The exported symbol `name`; throws cambium::Error naming the file when absent
    /// (`what` names the module in the message, e.g. "Cambium's MPI module").
    void* symbol(const char* name, const std::string& what) const;
};

/// dlopen's the first candidate that exists and loads; handle is null when none did, and
/// `reasons` then lists each existing candidate with dlerror's text (empty: none exists).
SharedModule load_module(const std::string& file_name, int dlopen_flags, std::string& reasons);

}  // namespace cambium
