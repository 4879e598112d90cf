// SPDX-License-Identifier: Apache-2.0
#include "base/shared_module.h"

#include <dlfcn.h>

#include "base/diagnostics.h"

namespace cambium {

namespace fs = std::filesystem;

std::vector<fs::path> module_candidates(const std::string& file_name)
{
    std::vector<fs::path> candidates;
    std::error_code error;
    fs::path exe = fs::read_symlink("/proc/self/exe", error);
    if (!error) {
        candidates.push_back(exe.parent_path() / file_name);
        candidates.push_back(exe.parent_path() / CAMBIUM_LIB_FROM_BIN / file_name);
    }
    // Code loaded as a shared object of its own (the Python module, installed in
    // P/lib/python3.X/dist-packages): the library folder P/lib two levels above it.
    Dl_info info{};
    if (dladdr(reinterpret_cast<void*>(&module_candidates), &info) && info.dli_fname) {
        fs::path self = fs::absolute(info.dli_fname, error);
        if (!error && self != exe)
            candidates.push_back(self.parent_path().parent_path().parent_path() / file_name);
    }
    candidates.push_back(fs::path(CAMBIUM_INSTALL_LIB_DIR) / file_name);
    candidates.push_back(fs::path(CAMBIUM_BUILD_MODULE_DIR) / file_name);
    return candidates;
}

void* SharedModule::symbol(const char* name, const std::string& what) const
{
    void* p = dlsym(handle, name);
    if (!p)
        throw Error(FileLoc{file.string()}, "is not " + what + ": it has no " + name);
    return p;
}

SharedModule load_module(const std::string& file_name, int dlopen_flags, std::string& reasons)
{
    SharedModule module;
    for (const fs::path& candidate : module_candidates(file_name)) {
        std::error_code error;
        if (!fs::exists(candidate, error))
            continue;
        module.handle = dlopen(candidate.c_str(), dlopen_flags);
        if (module.handle) {
            module.file = candidate;
            return module;
        }
        reasons += "\n  " + candidate.string() + ": " + dlerror();
    }
    return module;
}

}  // namespace cambium
