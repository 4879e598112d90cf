// SPDX-License-Identifier: Apache-2.0
// The animation file (manual 5.3) and cpfg's frame selection, form by form.
#include <gtest/gtest.h>

#include "base/diagnostics.h"
#include "geom/animation_file.h"

namespace cambium::geom {
namespace {

std::vector<int> numbers(const std::vector<AnimationFrame>& frames)
{
    std::vector<int> n;
    for (const AnimationFrame& f : frames)
        n.push_back(f.number);
    return n;
}

std::vector<int> frames_of(std::string_view text, int derivation_length = 10)
{
    return numbers(select_frames(parse_animation_file(text, "t.a"), derivation_length));
}

TEST(AnimationFile, ReadsEveryCommand)
{
    AnimationFile a = parse_animation_file("double buffer: off\n"
                                           "clear between frames: off\n"
                                           "scale between frames: on\n"
                                           "new view between frames: on\n"
                                           "center between frames: on\n"
                                           "hcenter between frames: on\n"
                                           "swap interval: 40\n"
                                           "first frame: 2\n"
                                           "last frame: 30 \n"
                                           "step: 4\n",
                                           "t.a");
    EXPECT_FALSE(a.double_buffer);
    EXPECT_FALSE(a.clear_between_frames);
    EXPECT_TRUE(a.scale_between_frames);
    EXPECT_TRUE(a.new_view_between_frames);
    EXPECT_TRUE(a.center_between_frames);
    EXPECT_TRUE(a.hcenter_between_frames);
    EXPECT_EQ(a.swap_interval, 40);
    EXPECT_EQ(a.first_frame, 2);
    EXPECT_EQ(a.last_frame, 30);
    EXPECT_EQ(a.step, 4);
}

TEST(AnimationFile, DefaultsAreCpfgs)
{
    AnimationFile a = default_animation();
    EXPECT_TRUE(a.double_buffer);
    EXPECT_TRUE(a.clear_between_frames);
    EXPECT_FALSE(a.scale_between_frames);
    EXPECT_FALSE(a.new_view_between_frames);
    // manual 4.2: frames 1 .. derivation length, step 1
    EXPECT_EQ(numbers(select_frames(a, 4)), (std::vector<int>{1, 2, 3, 4}));
}

TEST(AnimationFile, FirstLastStep)
{
    EXPECT_EQ(frames_of("first frame: 0\nlast frame: 12\nstep: 4\n"),
              (std::vector<int>{0, 4, 8, 12}));
    // the last frame is reached or passed: a step past it records one more frame
    EXPECT_EQ(frames_of("first frame: 1\nlast frame: 6\nstep: 2\n"),
              (std::vector<int>{1, 3, 5, 7}));
    // negative last frame: the derivation length (manual 4.2)
    EXPECT_EQ(frames_of("first frame: 8\nlast frame: -1\n", 10), (std::vector<int>{8, 9, 10}));
    // a last frame before the first is the first; step 0 or less is 1; first below 0 is 0
    EXPECT_EQ(frames_of("first frame: 5\nlast frame: 2\n"), (std::vector<int>{5}));
    EXPECT_EQ(frames_of("first frame: -3\nlast frame: 2\nstep: 0\n"),
              (std::vector<int>{0, 1, 2}));
}

TEST(AnimationFile, FrameDerivationSteps)
{
    auto frames = select_frames(parse_animation_file("first frame: 2\nlast frame: 8\nstep: 3\n",
                                                     "t.a"),
                                10);
    ASSERT_EQ(frames.size(), 3u);
    EXPECT_EQ(frames[0].derive_steps, 2);  // from the axiom
    EXPECT_EQ(frames[1].derive_steps, 3);
    EXPECT_EQ(frames[2].derive_steps, 3);
}

TEST(AnimationFile, IntervalsOfSingleFrames)
{
    EXPECT_EQ(frames_of("frame intervals: 2, 5, 9\n"), (std::vector<int>{2, 5, 9}));
}

TEST(AnimationFile, IntervalRangesWithoutStepUseTheFilesStep)
{
    EXPECT_EQ(frames_of("frame intervals: 1, 3-5, 8\n"), (std::vector<int>{1, 3, 4, 5, 8}));
    EXPECT_EQ(frames_of("step: 2\nframe intervals: 3-9\n"), (std::vector<int>{3, 5, 7, 9}));
}

TEST(AnimationFile, IntervalRangesWithStep)
{
    // the manual's example
    EXPECT_EQ(frames_of("frame intervals: 1, 3-5, 8-12 step 2, 25\n"),
              (std::vector<int>{1, 3, 4, 5, 8, 10, 12, 25}));
    // the corpus's 22-insect-realistic: 251 frames, the last one 500
    auto n = frames_of("first frame: 0\nlast frame: 500\nstep: 1\nframe intervals: 1-500 step 2\n");
    ASSERT_EQ(n.size(), 251u);
    EXPECT_EQ(n[0], 1);
    EXPECT_EQ(n[1], 3);
    EXPECT_EQ(n[249], 499);
    EXPECT_EQ(n[250], 500);
}

TEST(AnimationFile, IntervalsWinOverFirstAndLastFrame)
{
    EXPECT_EQ(frames_of("frame intervals: 4-6\nfirst frame: 0\nlast frame: 9\n"),
              (std::vector<int>{4, 5, 6}));
}

TEST(AnimationFile, IntervalRotateAccumulatesAfterEachFrame)
{
    auto frames = select_frames(
        parse_animation_file("frame intervals: 1-2, 3-5 rotate 1.5 0 -2\n", "t.a"), 10);
    ASSERT_EQ(numbers(frames), (std::vector<int>{1, 2, 3, 4, 5}));
    EXPECT_DOUBLE_EQ(frames[1].rotation_deg.x, 0);
    EXPECT_DOUBLE_EQ(frames[2].rotation_deg.x, 1.5);
    EXPECT_DOUBLE_EQ(frames[4].rotation_deg.x, 4.5);
    EXPECT_DOUBLE_EQ(frames[4].rotation_deg.z, -6);
}

TEST(AnimationFile, IntervalScaleMultipliesAfterEachFrame)
{
    auto frames = select_frames(
        parse_animation_file("frame intervals: 1-3 step 1 scale 0.5 1 2\n", "t.a"), 10);
    ASSERT_EQ(frames.size(), 3u);
    EXPECT_DOUBLE_EQ(frames[0].scale.x, 1);
    EXPECT_DOUBLE_EQ(frames[2].scale.x, 0.25);
    EXPECT_DOUBLE_EQ(frames[2].scale.z, 4);
}

TEST(AnimationFile, StepZeroShowsFramesWithoutDeriving)
{
    auto frames = select_frames(
        parse_animation_file("frame intervals: 2-5 step 0 rotate 0 10 0\n", "t.a"), 10);
    ASSERT_EQ(numbers(frames), (std::vector<int>{2, 3, 4, 5}));
    EXPECT_EQ(frames[0].derive_steps, 2);
    EXPECT_EQ(frames[1].derive_steps, 0);
    EXPECT_EQ(frames[3].derive_steps, 0);
    EXPECT_DOUBLE_EQ(frames[3].rotation_deg.y, 30);
}

TEST(AnimationFile, MalformedValuesNameLineAndColumn)
{
    try {
        parse_animation_file("first frame: 1\nstep: many\n", "t.a");
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_EQ(e.loc().line, 2);
        EXPECT_EQ(e.loc().column, 7);
    }
    EXPECT_THROW(parse_animation_file("double buffer: maybe\n", "t.a"), Error);
    EXPECT_THROW(parse_animation_file("frame intervals: 5-2\n", "t.a"), Error);
    EXPECT_THROW(parse_animation_file("frame intervals: 1-5 turn 3\n", "t.a"), Error);
    EXPECT_THROW(parse_animation_file("frame intervals: 1-5 rotate 1 2\n", "t.a"), Error);
    EXPECT_THROW(parse_animation_file("last frame: 3 4\n", "t.a"), Error);
}

TEST(AnimationFile, UnknownCommandsAreSkipped)
{
    set_warnings_enabled(false);
    AnimationFile a = parse_animation_file("colour: red\nframe numbers: consecutive\nstep: 2\n",
                                           "t.a");
    set_warnings_enabled(true);
    EXPECT_EQ(a.step, 2);
}

TEST(AnimationFile, TooManyFramesIsAnError)
{
    AnimationFile a = parse_animation_file("first frame: 0\nlast frame: 2000\n", "t.a");
    EXPECT_THROW(select_frames(a, 1, 1000), Error);
    EXPECT_EQ(select_frames(a, 1, 2001).size(), 2001u);
}

/// The column of the error `text` gives, with its message checked for `words`.
int error_column(const std::string& text, const std::string& words)
{
    try {
        parse_animation_file(text, "t.a");
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
        return e.loc().column;
    }
    ADD_FAILURE() << "no error for " << text;
    return 0;
}

// A rotate or scale the camera cannot take is an error at its column before any frame,
// not a failed camera after some frames were written.
TEST(AnimationFile, RotateAndScaleAreFiniteNumbers)
{
    EXPECT_EQ(error_column("frame intervals: 1-3 rotate nan 0 0\n", "expected a number, found 'nan'"), 29);
    EXPECT_EQ(error_column("frame intervals: 1-3 scale 1 inf 1\n", "found 'inf'"), 30);
    EXPECT_EQ(error_column("frame intervals: 1-3 rotate 0 0 1.7e308\n", "found '1.7e308'"), 33);
    // each value fits, their sum or product after two frames does not
    AnimationFile a = parse_animation_file("frame intervals: 1-3 rotate 3e38 0 0\n", "t.a");
    try {
        select_frames(a, 10);
        ADD_FAILURE() << "no error";
    } catch (const Error& e) {
        EXPECT_EQ(e.loc().file, "t.a");
        EXPECT_EQ(e.loc().line, 1);
        EXPECT_EQ(e.loc().column, 29);
    }
    EXPECT_THROW(select_frames(parse_animation_file("frame intervals: 1-9 scale 1e30 1 1\n", "t.a"), 10),
                 Error);
    EXPECT_NO_THROW(select_frames(parse_animation_file("frame intervals: 1-9 rotate 1e30 0 0\n", "t.a"), 10));
}

// Frame numbers and steps are derivation steps: past the derivation length's limit
// they are errors at their column, not billions of steps derived without a word.
TEST(AnimationFile, FrameNumbersAndStepsAreBounded)
{
    EXPECT_EQ(error_column("first frame: 2000000000\n", "from -1000000 to 1000000"), 14);
    EXPECT_EQ(error_column("last frame: 1000001\n", "not 1000001"), 13);
    EXPECT_EQ(error_column("step: 2000000000\n", "the step must be"), 7);
    EXPECT_EQ(error_column("frame intervals: 1-5, 7-2000000000\n", "last frame of the range"), 25);
    EXPECT_EQ(error_column("frame intervals: 1-5 step 1000001\n", "step of the range"), 27);
    EXPECT_EQ(error_column("frame intervals: 3000000\n", "a frame number"), 18);
    EXPECT_EQ(parse_animation_file("first frame: 1000000\nlast frame: -1\n", "t.a").first_frame,
              1000000);
    std::string many = "frame intervals: ";
    for (std::size_t i = 0; i <= max_frame_intervals; ++i)
        many += "1,";
    many += "1\n";
    EXPECT_EQ(error_column(many, "more than 1000000 frame intervals"),
              int(17 + 2 * max_frame_intervals + 1));
}

// Intervals that hold no frame ahead are passed once, not once per frame: 200 000 of
// them before a range of 200 000 frames would take 4·10¹⁰ comparisons otherwise.
TEST(AnimationFile, DeadIntervalsAreSkippedOnce)
{
    std::string text = "frame intervals: ";
    for (int i = 0; i < 200000; ++i)
        text += "0, ";
    text += "1-200000\n";
    std::vector<int> frames = numbers(select_frames(parse_animation_file(text, "t.a"), 1));
    ASSERT_EQ(frames.size(), 200001u);
    EXPECT_EQ(frames[1], 1);
    EXPECT_EQ(frames.back(), 200000);
}

}  // namespace
}  // namespace cambium::geom
