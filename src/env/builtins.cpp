// SPDX-License-Identifier: Apache-2.0
// The built-in environments, found by the executable's file name.
#include "env/builtins.h"

#include <filesystem>

namespace cambium::env {

std::unique_ptr<Environment> make_builtin(const std::string& program,
                                          const std::vector<std::string>& args,
                                          const Context& context)
{
    using Maker = std::unique_ptr<Environment> (*)(const std::vector<std::string>&, const Context&);
    struct Entry {
        const char* name;
        Maker make;
    };
    static constexpr Entry builtins[] = {
        {"honda81", make_honda81},
        {"ecosystem", make_ecosystem},
        {"chiba", make_chiba},
        {"clover", make_clover},
    };
    const std::string name = std::filesystem::path(program).filename().string();
    for (const Entry& e : builtins)
        if (name == e.name)
            return e.make(args, context);
    return nullptr;
}

}  // namespace cambium::env
