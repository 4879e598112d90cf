// SPDX-License-Identifier: Apache-2.0
// The corpus's models as the tests see them: folder, cpfg command line, oracle folder.
#include "corpus_model.h"

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <unistd.h>

#include "base/diagnostics.h"

namespace cambium::test {

namespace fs = std::filesystem;

std::optional<fs::path> corpus_dir()
{
    const char* env = std::getenv("CAMBIUM_CORPUS");
    fs::path dir = env ? fs::path(env) : fs::path(CAMBIUM_CORPUS_DEFAULT);
    if (!fs::exists(dir / "cpfg"))
        return std::nullopt;
    return dir;
}

std::vector<CorpusModel> corpus_models(const fs::path& corpus)
{
    std::vector<CorpusModel> models;
    for (const auto& entry : fs::recursive_directory_iterator(corpus / "cpfg")) {
        if (entry.path().filename() != "model.json")
            continue;
        std::ifstream in(entry.path());
        nlohmann::json json = nlohmann::json::parse(in);
        CorpusModel m;
        m.id = json.at("id").get<std::string>();
        m.folder = entry.path().parent_path();
        m.oracle = corpus / "oracle" / m.id;
        m.environmental = json.value("env_program", false);
        std::istringstream words(json.at("command").get<std::string>());
        std::string word;
        words >> word;  // "cpfg"
        while (words >> word)
            m.command.push_back(word);
        models.push_back(std::move(m));
    }
    std::sort(models.begin(), models.end(),
              [](const CorpusModel& a, const CorpusModel& b) { return a.id < b.id; });
    return models;
}

app::Options model_options(const CorpusModel& model)
{
    app::Options o = *app::parse_command_line(model.command);
    auto absolute = [&](fs::path& p) { p = model.folder / p; };
    absolute(o.lsystem);
    absolute(o.view);
    if (o.animation)
        absolute(*o.animation);
    if (o.environment_file)
        absolute(*o.environment_file);
    for (auto& f : o.colour_files)
        absolute(f.file);
    o.quiet = true;
    return o;
}

std::string without_newlines(std::string s)
{
    std::erase(s, '\n');
    std::erase(s, '\r');
    return s;
}

std::string string_difference(const std::string& ours, const std::string& cpfg)
{
    if (ours == cpfg)
        return {};
    std::size_t at = 0;
    while (at < ours.size() && at < cpfg.size() && ours[at] == cpfg[at])
        ++at;
    return "at character " + std::to_string(at) + ": ours '" + ours.substr(at, 40) +
           "' cpfg '" + cpfg.substr(at, 40) + "'";
}

std::string read_text(const fs::path& file)
{
    std::ifstream in(file, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

std::optional<int> for_each_oracle_model(
    const std::string& oracle_file,
    const std::function<void(const CorpusModel&, const fs::path&)>& visit)
{
    auto corpus = corpus_dir();
    if (!corpus)
        return std::nullopt;
    int total = 0;
    set_warnings_enabled(false);
    for (const CorpusModel& model : corpus_models(*corpus)) {
        fs::path reference = model.oracle / oracle_file;
        if (!fs::exists(reference))
            continue;
        ++total;
        visit(model, reference);
    }
    set_warnings_enabled(true);
    return total;
}

fs::path process_folder(const std::string& name)
{
    const fs::path dir = fs::temp_directory_path() / ("cambium_" + name + "_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

std::optional<int> sweep_self_contained_models(
    const std::function<void(const CorpusModel&, app::Options)>& visit)
{
    auto corpus = corpus_dir();
    if (!corpus)
        return std::nullopt;
    int total = 0;
    set_warnings_enabled(false);
    for (const CorpusModel& model : corpus_models(*corpus)) {
        if (model.environmental)
            continue;
        ++total;
        try {
            app::Options options = model_options(model);
            options.max_modules = 5'000'000;
            visit(model, std::move(options));
        } catch (const std::exception& e) {
            ADD_FAILURE() << model.id << ": " << e.what();
        }
    }
    set_warnings_enabled(true);
    return total;
}

void compare_with_oracle(
    const std::string& oracle_file, const std::set<std::string>& known,
    const std::function<std::string(const CorpusModel&, const std::string&)>& compare)
{
    int matched = 0;
    std::optional<int> total = for_each_oracle_model(oracle_file, [&](const CorpusModel& model,
                                                                      const fs::path& reference) {
        std::string difference;
        try {
            difference = compare(model, read_text(reference));
        } catch (const std::exception& e) {
            difference = e.what();
        }
        if (difference.empty()) {
            ++matched;
            // keeps the known lists (and docs/deviations.md) honest
            EXPECT_FALSE(known.count(model.id)) << model.id << " matches now: take it off the known list";
            return;
        }
        std::printf("  %s differs: %s\n", model.id.c_str(), difference.c_str());
        if (!known.count(model.id))
            ADD_FAILURE() << model.id << ": " << difference;
    });
    if (!total)
        GTEST_SKIP() << "corpus not found";
    std::printf("%d of %d models match\n", matched, *total);
    EXPECT_GT(*total, 0);
}

}  // namespace cambium::test
