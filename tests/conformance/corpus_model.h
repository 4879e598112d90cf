// SPDX-License-Identifier: Apache-2.0
// The corpus's models as the tests see them: folder, cpfg command line, oracle folder.
#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "app/command_line.h"

namespace cambium::test {

struct CorpusModel {
    std::string id;                  ///< "11-CPFG/01-Introduction/01-quadratic-Koch"
    std::filesystem::path folder;    ///< corpus/cpfg/<id>
    std::filesystem::path oracle;    ///< corpus/oracle/<id> (may not exist)
    std::vector<std::string> command;  ///< cpfg's arguments, without "cpfg"
    bool environmental = false;      ///< talks to an environmental program (?E)
};

/// The corpus folder ($CAMBIUM_CORPUS or the build's default), if it exists.
std::optional<std::filesystem::path> corpus_dir();

/// Every model of corpus/cpfg with a model.json, sorted by id.
std::vector<CorpusModel> corpus_models(const std::filesystem::path& corpus);

/// The model's command line parsed by Cambium's own parser, with the files it names
/// made absolute (relative to the model's folder).
app::Options model_options(const CorpusModel& model);

/// `s` without line breaks (cpfg's string files break lines).
std::string without_newlines(std::string s);

/// "" when the strings are equal, else where they first differ and what follows there.
std::string string_difference(const std::string& ours, const std::string& cpfg);

/// The text of a file (empty when it cannot be read).
std::string read_text(const std::filesystem::path& file);

/// Calls visit(model, reference) for every corpus model whose oracle folder holds
/// `oracle_file` (reference: that file), warnings silenced meanwhile. Returns how many models
/// it visited, or nullopt when the corpus is not found.
std::optional<int> for_each_oracle_model(
    const std::string& oracle_file,
    const std::function<void(const CorpusModel&, const std::filesystem::path&)>& visit);

/// A folder of this process's own under the temporary directory (cambium_NAME_PID, made
/// empty): tests run in parallel, in other checkouts too.
std::filesystem::path process_folder(const std::string& name);

/// Calls visit(model, options) for every corpus model that needs no environmental
/// program, its options parsed from its command line with the sweeps' memory bound (5
/// million modules); warnings are silenced meanwhile, and an exception fails the test
/// naming the model. Returns how many models it visited, or nullopt when the corpus is
/// not found.
std::optional<int> sweep_self_contained_models(
    const std::function<void(const CorpusModel&, app::Options)>& visit);

/// Runs `compare(model, reference text)` on every model whose oracle folder holds
/// `oracle_file`; compare returns "" when the model matches, else what differs (an
/// exception counts as a difference). Prints each difference and "N of M models match",
/// and fails the test for every difference not in `known`.
void compare_with_oracle(
    const std::string& oracle_file, const std::set<std::string>& known,
    const std::function<std::string(const CorpusModel&, const std::string&)>& compare);

}  // namespace cambium::test
