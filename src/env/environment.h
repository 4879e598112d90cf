// SPDX-License-Identifier: Apache-2.0
// Open L-systems (manual chapter 7): what the environmental step sends for each ?E
// module, what comes back, and the environments that answer it.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "base/diagnostics.h"
#include "geom/view_file.h"
#include "lsys/lsystem.h"

namespace cambium::env {

/// One turtle vector as a `.e` format string sent it: the values an environmental
/// program reads back (sscanf "%f %f %f" after the format's literal prefix), and how
/// many it read (0 when the `.e` file does not ask for this vector).
struct SentVector {
    std::array<float, 3> values{};
    int count = 0;
};

/// A module as sent: its name ("?E", "F", "@Gs") and its parameters as cpfg's "%g"
/// text reads back (six significant digits).
struct SentModule {
    std::string symbol;
    std::vector<float> params;
};

/// One communication module's message (manual 7.4.3), every number already quantised as
/// cpfg's text protocol quantises it, so a built-in computes from what a program would read.
struct Query {
    std::uint64_t address = 0;            ///< cpfg's address: bytes from the pass's first ?E
    SentModule module;                    ///< the ?E itself
    std::optional<SentModule> following;  ///< the next module (`following module: yes`)
    SentVector position, heading, left, up;
    SentVector line_width, scale_factor;  ///< one value each
    /// `interpreted modules:`: the GLS `polygon` statements of the module after the ?E
    /// (its whole homomorphism successor) when that module is one the `.e` names; nullopt
    /// when it is not (a program then expects no geometry block).
    std::optional<std::vector<std::string>> geometry;
    /// The organ the ?E stands before: the index, in the derived string, of the module
    /// that follows it (what an environment computing on the plant's own geometry
    /// answers for: the primitives geom's provenance gives that module).
    std::uint64_t organ = 0;
    /// The plant that sent it, in a shared environment (0 alone).
    std::size_t plant = 0;
};

/// A reply: the ?E at `address` gets each given parameter; nullopt (an empty field)
/// leaves that parameter unchanged. Values are quantised through "%g" by the caller.
struct Reply {
    std::uint64_t address = 0;
    std::vector<std::optional<float>> params;
};

/// An 8-bit RGB image, rows top to bottom (what a built-in reads from an image file).
struct RgbImage {
    int width = 0, height = 0;
    std::vector<std::uint8_t> rgb;  ///< width * height * 3
};

/// What an environment may use beside its own arguments.
struct Context {
    /// The model's folder: programs run there and relative file names are read there.
    std::filesystem::path folder;
    /// Files outside `folder` may be read (--allow-file-access).
    bool allow_file_access = false;
    /// Reads an image file (SGI .rgb, Targa, PNG, ...); throws cambium::Error naming it.
    std::function<RgbImage(const std::filesystem::path&)> read_image;
};

/// The plant of one environmental pass as the turtle reads it: for an environment that
/// computes on the plant's own geometry rather than on the messages alone.
struct PassPlant {
    const lsys::TurtleString& string;
    const lsys::SymbolTable& symbols;
    const geom::ViewFile& view;
    /// The plant's number in a shared environment (0 alone), as its queries carry it.
    std::size_t plant = 0;
    /// Where the plant stands (a 3x4 column-major transform); null: at the origin.
    const std::array<float, 12>* placement = nullptr;
};

/// An environmental process: cpfg's external program or one of Cambium's built-ins.
/// It keeps its state from pass to pass, as a program started once for the run does.
class Environment {
public:
    virtual ~Environment() = default;
    /// One environmental pass: every ?E of the string, in string order; `step` is the
    /// step counter cpfg sends at the pass's end (0 for the axiom's pass). Replies may
    /// come in any order; a reply to an address that was not sent is ignored.
    virtual std::vector<Reply> pass(const std::vector<Query>& queries, int step) = 0;
    /// The pass's plant, before pass() (also at a step without ?E: the plant is still
    /// there); only valid during the call. In a shared environment every plant's thread
    /// calls it, at once. A program sees only the messages, so the default ignores it.
    virtual void observe(const PassPlant& /*plant*/) {}
    /// A step whose string holds no ?E: cpfg sends nothing, so an environment of its
    /// own sees nothing; one shared by several plants counts this plant as done.
    virtual void idle(int /*step*/) {}
};

/// One `keyword: value` line of a built-in's specification file (vlab's `.spec` files).
struct SpecLine {
    std::string keyword;  ///< the text before the first ':', as written (case kept)
    std::string value;    ///< the text after it, leading blanks removed
    FileLoc loc;          ///< the line (column of the value)
};

/// The `keyword: value` lines of a specification file named by a built-in's argument,
/// relative to the model folder and confined to it unless file access is allowed. Lines
/// without ':' are returned with an empty value. Errors name the file.
std::vector<SpecLine> read_spec_file(const std::filesystem::path& file, const Context& context);

/// The file an argument names, relative to the model folder; Error when it lies outside
/// the folder and file access is not allowed, or when it is not a regular file.
std::filesystem::path model_file(const std::string& name, const Context& context);

/// Warns about a keyword a program would ignore: "<program>: <file>:<line>: unknown
/// keyword 'x' ignored".
void warn_unknown_keyword(const std::string& program, const SpecLine& line);

}  // namespace cambium::env
