// SPDX-License-Identifier: Apache-2.0
// Turns model files into seeds for targets whose input is not a model file as written:
//   cambium_fuzz_seed lsystem OUT_DIR FILE.l...   the .l files run through the preprocessor
//   cambium_fuzz_seed strb OUT_DIR FILE.str...    text strings rewritten in binary
// (scripts/fuzz.sh calls it; a file it cannot convert is skipped with a message.)
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "base/diagnostics.h"
#include "lsys/preprocessor.h"
#include "lsys/string_io.h"

namespace {

namespace fs = std::filesystem;

std::string read_all(const fs::path& file)
{
    std::ifstream in(file, std::ios::binary);
    std::ostringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

std::string convert(const std::string& mode, const fs::path& file)
{
    using namespace cambium::lsys;
    if (mode == "lsystem") {
        PreprocessOptions options;
        options.include_dirs.push_back(file.parent_path().empty() ? "." : file.parent_path());
        return preprocess(read_all(file), file.filename().string(), options);
    }
    SymbolTable symbols;
    ModuleString string = read_string_text(file, symbols);
    std::ostringstream out;
    write_string_binary(string, symbols, out);
    return out.str();
}

}  // namespace

int main(int argc, char** argv)
{
    if (argc < 3 || (std::string(argv[1]) != "lsystem" && std::string(argv[1]) != "strb")) {
        std::fprintf(stderr, "usage: %s lsystem|strb OUT_DIR FILE...\n", argv[0]);
        return 2;
    }
    cambium::set_warnings_enabled(false);
    fs::path out_dir = argv[2];
    fs::create_directories(out_dir);
    int written = 0;
    for (int i = 3; i < argc; ++i) {
        try {
            std::string seed = convert(argv[1], argv[i]);
            std::ofstream(out_dir / ("seed" + std::to_string(i - 2)), std::ios::binary) << seed;
            ++written;
        } catch (const std::exception& e) {
            std::fprintf(stderr, "seed: skipped %s: %s\n", argv[i], e.what());
        }
    }
    std::printf("seed: %d %s seeds in %s\n", written, argv[1], out_dir.c_str());
    return 0;
}
