// SPDX-License-Identifier: Apache-2.0
// External environmental programs: cpfg's pipe protocol with a test program, and every
// way a program can fail ending the run with an error that names it, in bounded time.
#include "env/external_program.h"

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "env/comm_spec.h"
#include "env_fixture.h"

namespace cambium::env {
namespace {

namespace fs = std::filesystem;

/// A model folder with plant.e naming the test program in `mode`.
struct Model {
    Context context;
    CommSpec spec;
};

Model model(const std::string& test, const std::string& mode, const std::string& extra = "")
{
    Model m;
    m.context =
        testing::model_with("ext_" + test, "plant.e",
                            std::string("executable: ") + CAMBIUM_TEST_PROGRAM + " " + mode +
                                "\n"
                                "turtle position:P:%g %g %g\n" +
                                extra);
    m.spec = read_comm_spec(m.context.folder / "plant.e");
    return m;
}

std::vector<Query> queries(std::size_t n, std::size_t params = 1)
{
    std::vector<Query> out;
    for (std::size_t i = 0; i < n; ++i) {
        Query q = testing::query_at(i * 3, {float(i) + 0.5f, 2, 3}, std::vector<float>(params, 9));
        q.following = SentModule{"F", {1.25f}};
        out.push_back(q);
    }
    return out;
}

ExternalLimits quick()
{
    ExternalLimits l;
    l.seconds_per_pass = 1;
    return l;
}

/// The message of the Error `f` throws ("" when none).
template <class F>
std::string error_of(F f)
{
    try {
        f();
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

std::string read_file(const fs::path& p)
{
    std::ifstream in(p);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

TEST(ExternalProgram, EchoAnswersEveryQueryAndSaysGoodbye)
{
    Model m = model("echo", "echo");
    {
        auto env = make_external_program(m.spec, m.context, {});
        for (int step : {0, 1}) {
            const auto replies = env->pass(queries(3), step);
            const auto x = testing::first_params(replies);
            ASSERT_EQ(x.size(), 3u);
            EXPECT_EQ(x.at(0), 0.5f);
            EXPECT_EQ(x.at(3), 1.5f);
            EXPECT_EQ(x.at(6), 2.5f);
        }
    }
    // cpfg's argument order, in the model folder; the goodbye ends it after both steps
    EXPECT_EQ(read_file(m.context.folder / "started.txt"), "-e plant.e echo\n");
    EXPECT_EQ(read_file(m.context.folder / "goodbye.txt"), "0\n1\n");
}

TEST(ExternalProgram, PolygonsTravelBetweenDbeginAndDend)
{
    // chunks of two queries: the blocks belong to their query whatever the chunking
    Model m = model("polygons", "polygons", "communication type: pipes 2\ninterpreted modules: all\n");
    std::vector<Query> q = queries(5, 2);
    q[0].geometry = {"polygon 0 0 0 1 0 0 0 3 0"};
    q[2].geometry = std::vector<std::string>{};  // named, but it draws nothing
    q[3].geometry = {"polygon 0 0 0 1 0 0 0 1 0", "polygon 0 0 0 1 0 0 0 -2 0 0 7 1"};
    std::map<std::uint64_t, std::pair<float, float>> answers;
    for (const Reply& r : make_external_program(m.spec, m.context, quick())->pass(q, 0))
        answers[r.address] = {*r.params.at(0), *r.params.at(1)};
    ASSERT_EQ(answers.size(), 5u);
    EXPECT_EQ(answers[0], std::make_pair(1.0f, 3.0f));
    EXPECT_EQ(answers[3], std::make_pair(0.0f, 0.0f));
    EXPECT_EQ(answers[6], std::make_pair(0.0f, 0.0f));
    EXPECT_EQ(answers[9], std::make_pair(2.0f, 7.0f));
    EXPECT_EQ(answers[12], std::make_pair(0.0f, 0.0f));
}

TEST(ExternalProgram, NoAnswersEmptyFieldsAndUnknownAddresses)
{
    Model nothing = model("nothing", "nothing");
    EXPECT_TRUE(
        make_external_program(nothing.spec, nothing.context, quick())->pass(queries(4), 0).empty());

    Model empty = model("empty", "empty");
    const auto replies =
        make_external_program(empty.spec, empty.context, quick())->pass(queries(2, 3), 0);
    ASSERT_EQ(replies.size(), 2u);
    EXPECT_EQ(replies[1].address, 3u);
    ASSERT_EQ(replies[1].params.size(), 3u);
    EXPECT_FALSE(replies[1].params[0] || replies[1].params[1] || replies[1].params[2]);

    Model unknown = model("unknown", "unknown");
    const auto strays =
        make_external_program(unknown.spec, unknown.context, quick())->pass(queries(2), 0);
    ASSERT_EQ(strays.size(), 2u);
    EXPECT_EQ(strays[0].address, 1000000u);  // passed on: the environmental step ignores it
}

TEST(ExternalProgram, ManyQueriesTravelInChunksAndInOne)
{
    // 10^4 queries are about 300 KiB and their answers 170 KiB, both more than a pipe
    // holds: the program answers each at once, so one chunk works only if we read while
    // writing
    ExternalLimits limits;
    limits.seconds_per_pass = 20;
    for (const std::string type : {"pipes", "pipes 100000"}) {
        Model m = model("chunks", "echo", "communication type: " + type + "\n");
        auto env = make_external_program(m.spec, m.context, limits);
        const auto x = testing::first_params(env->pass(queries(10000, 3), 7));
        ASSERT_EQ(x.size(), 10000u) << type;
        EXPECT_EQ(x.at(3 * 9999), 9999.5f);
    }
}

TEST(ExternalProgram, AnswersAfterTheLastChunkMayComeInChunks)
{
    Model m = model("later", "later");
    const auto x = testing::first_params(
        make_external_program(m.spec, m.context, quick())->pass(queries(250), 1));
    ASSERT_EQ(x.size(), 250u);
    EXPECT_EQ(x.at(3 * 249), 249.5f);
}

TEST(ExternalProgram, AHangingProgramEndsAtTheTimeLimit)
{
    Model m = model("hang", "hang");
    auto env = make_external_program(m.spec, m.context, quick());
    const auto start = std::chrono::steady_clock::now();
    const std::string e = error_of([&] { env->pass(queries(5), 4); });
    EXPECT_NE(e.find("did not answer within 1 s at step 4"), std::string::npos) << e;
    EXPECT_NE(e.find("test_program"), std::string::npos) << e;
    EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(10));
    EXPECT_NE(error_of([&] { env->pass(queries(5), 5); }).find("failed before"), std::string::npos);
}

TEST(ExternalProgram, FailuresNameTheProgramAndWhatHappened)
{
    struct Case {
        std::string mode, expected;
    };
    ExternalLimits small = quick();
    small.max_pass_bytes = 1u << 20;
    for (const Case& c : {Case{"die", "closed its output at step 0 (it exited with status 3)"},
                          Case{"flood", "wrote more than 1048576 bytes at step 0"},
                          Case{"long", "wrote a line longer than 65536 bytes"},
                          Case{"garbage", "answered 'hello, plant' at step 0"},
                          Case{"twice", "answered more often than the 3 ?E modules sent at step 0"},
                          Case{"deaf", "stopped reading its input at step 0"},
                          Case{"mute", "did not send its start-up byte within 1 s"},
                          Case{"bad-start", "sent 88 instead of its start-up byte 1"}}) {
        Model m = model(c.mode, c.mode);
        const std::string e =
            error_of([&] { make_external_program(m.spec, m.context, small)->pass(queries(3), 0); });
        EXPECT_NE(e.find(c.expected), std::string::npos) << c.mode << ": " << e;
        EXPECT_NE(e.find("plant.e"), std::string::npos) << e;
    }
}

TEST(ExternalProgram, OtherCommunicationTypesSpeakPipesThroughAPrivateCopy)
{
    Model m = model("files", "echo", "communication type: files 3\nverbose: off\n");
    fs::path copy;
    {
        auto env = make_external_program(m.spec, m.context, quick());
        EXPECT_EQ(testing::first_params(env->pass(queries(7), 0)).size(), 7u);  // chunks of 3
        std::istringstream started(read_file(m.context.folder / "started.txt"));
        std::string e;
        started >> e >> copy;
        EXPECT_EQ(e, "-e");
        EXPECT_EQ(copy.filename(), "plant.e");
        EXPECT_NE(copy.parent_path(), m.context.folder);
    }
    const std::string seen = read_file(m.context.folder / "e-file.txt");
    EXPECT_NE(seen.find("communication type: pipes 3\nverbose: off\n"), std::string::npos) << seen;
    EXPECT_NE(seen.find("turtle position:P:%g %g %g\n"), std::string::npos) << seen;
    EXPECT_FALSE(fs::exists(copy.parent_path()));
}

TEST(ExternalProgram, AMissingProgramIsAnError)
{
    Model missing = model("missing", "echo");
    missing.spec.executable = {"./no-such-environment"};
    EXPECT_NE(error_of([&] {
                  make_external_program(missing.spec, missing.context, quick());
              }).find("cannot start"),
              std::string::npos);
}

TEST(ExternalProgram, WritesEachPassToTheMessageFolder)
{
    Model m = model("log", "echo");
    ExternalLimits limits = quick();
    limits.message_folder = m.context.folder / "messages";
    prepare_message_folder(limits.message_folder);
    {
        auto env = make_external_program(m.spec, m.context, limits);
        env->pass(queries(1, 2), 3);
    }
    EXPECT_EQ(read_file(limits.message_folder / "step003.to"),
              "0 E(9,9)F(1.25)\nP:0.5 2 3\nControl: 5 3\n");
    EXPECT_EQ(read_file(limits.message_folder / "step003.from"), "0 E(0.5)\nControl: 5\n");
    EXPECT_EQ(fs::status(limits.message_folder / "step003.to").permissions() & fs::perms::all,
              fs::perms::owner_read | fs::perms::owner_write);

    // 150 queries: a first chunk of 100 with step 0, then the last with the step
    {
        auto env = make_external_program(m.spec, m.context, limits);
        env->pass(queries(150), 3);
    }
    const std::string sent = read_file(limits.message_folder / "step003-2.to");
    const std::size_t first_end = sent.find("Control: 1 0\n");
    ASSERT_NE(first_end, std::string::npos);
    EXPECT_NE(sent.rfind("297 E(9)F(1.25)\n", first_end), std::string::npos);  // the 100th
    EXPECT_EQ(sent.find("300 E(9)"), first_end + 13);                          // the 101st
    EXPECT_EQ(sent.substr(sent.size() - 13), "Control: 4 3\n");

    // not empty, or a link: refused
    EXPECT_NE(error_of([&] { prepare_message_folder(limits.message_folder); }).find("not empty"),
              std::string::npos);
    fs::create_directory_symlink(m.context.folder, m.context.folder / "link");
    EXPECT_NE(error_of([&] { prepare_message_folder(m.context.folder / "link"); }).find("link"),
              std::string::npos);
}

}  // namespace
}  // namespace cambium::env
