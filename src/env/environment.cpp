// SPDX-License-Identifier: Apache-2.0
// The pieces every environment shares: its files, read as vlab's programs read them.
#include "env/environment.h"


#include "base/confinement.h"
#include "env/spec_values.h"
#include "geom/text_input.h"

namespace cambium::env {

std::filesystem::path model_file(const std::string& name, const Context& context)
{
    namespace fs = std::filesystem;
    const fs::path named = fs::path(name).is_absolute() ? fs::path(name) : context.folder / name;
    if (!context.allow_file_access && !lies_within(named, context.folder))
        throw Error(FileLoc{named.string()},
                    "the environment's file lies outside the model's folder " +
                        context.folder.string() + " (--allow-file-access lifts this)");
    return named;
}

std::vector<SpecLine> read_spec_file(const std::filesystem::path& file, const Context& context)
{
    const std::filesystem::path path = model_file(file.string(), context);
    const std::string text = geom::read_text_file(path, "specification file");
    std::vector<SpecLine> lines;
    for (const auto& [number, line] : non_blank_lines(text)) {
        SpecLine spec;
        const std::size_t colon = line.find(':');
        spec.keyword = line.substr(0, colon);
        std::size_t value = colon == std::string::npos ? line.size() : colon + 1;
        value = std::min(line.size(), line.find_first_not_of(" \t", value));
        spec.value = line.substr(value);
        spec.loc = FileLoc{path.string(), number, static_cast<int>(value) + 1};
        lines.push_back(std::move(spec));
    }
    return lines;
}

void warn_unknown_keyword(const std::string& program, const SpecLine& line)
{
    warn(FileLoc{line.loc.file, line.loc.line, 1},
         program + ": unknown keyword '" + line.keyword + "' ignored");
}

}  // namespace cambium::env
