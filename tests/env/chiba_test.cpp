// SPDX-License-Identifier: Apache-2.0
// The built-in chiba (light reaching leaf balls) on hand-made cases whose answers
// follow from what vlab's program computes (docs/environment.md).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "env_fixture.h"

namespace cambium::env {
namespace {

using testing::first_params;
using testing::model_with;
using testing::query_at;

std::unique_ptr<Environment> chiba(const std::string& test, const std::string& spec)
{
    Context context = model_with("chiba_" + test, "light.spec", spec);
    return make_builtin("chiba", {"light.spec"}, context);
}

// light from straight above (+y), one voxel grid of 4 a side
const std::string overhead = "grid size: 4x4x4\nsource direction: 0 1 0 1\n";

TEST(Chiba, ALoneBallReceivesAllTheLight)
{
    // intensities 1, 1, 2 are normalised to 1/4, 1/4, 1/2, which sum to 1 exactly
    auto env = chiba("lone", "source direction: 0 1 0 1\nsource direction: 1 1 0 1\nsource direction: 0 1 1 2\n");
    auto answers = first_params(env->pass({query_at(5, {3, 4, 5}, {1})}, 0));
    EXPECT_EQ(answers.at(5), 1.0f);
}

TEST(Chiba, ABallUnderAnotherGetsTheTransmittedLight)
{
    // equal balls on one vertical: the upper one's disc covers the lower one's whole
    // disc, so the lower one gets 1 - (1 - t) = t; the walk meets the upper ball in
    // several voxels but counts it once (t, not a power of t)
    auto env = chiba("under", overhead + "transmittance: 0.25\nestimate intersection area: on\n");
    auto answers = first_params(env->pass({query_at(1, {0, 0, 0}, {1}), query_at(2, {0, 3, 0}, {1})}, 0));
    EXPECT_EQ(answers.at(1), 0.25f);
    EXPECT_EQ(answers.at(2), 1.0f);
}

TEST(Chiba, WithoutAreasTheChordThroughABallDecidesThePower)
{
    // the ray crosses the upper ball along its diameter 2r: t^(2r / 2r) = t
    auto env = chiba("chord", overhead + "transmittance: 0.25\n");
    auto answers = first_params(env->pass({query_at(1, {0, 0, 0}, {1}), query_at(2, {0, 3, 0}, {1})}, 0));
    EXPECT_EQ(answers.at(1), 0.25f);
    EXPECT_EQ(answers.at(2), 1.0f);
    // from inside an overlapping ball only the chord ahead counts: 1.5 of the diameter 2
    auto inside = chiba("chord_inside", overhead + "transmittance: 0.25\n");
    answers = first_params(inside->pass({query_at(1, {0, 0, 0}, {1}), query_at(2, {0, 0.5f, 0}, {1})}, 0));
    EXPECT_NEAR(answers.at(1), std::pow(0.25, 0.75), 1e-6);
}

TEST(Chiba, TransmittanceOneShadesNothing)
{
    for (const char* mode : {"estimate intersection area: on\n", ""}) {
        auto env = chiba("clear", overhead + "transmittance: 1\n" + mode);
        auto answers = first_params(env->pass({query_at(1, {0, 0, 0}, {1}), query_at(2, {0, 3, 0}, {1})}, 0));
        EXPECT_EQ(answers.at(1), 1.0f) << mode;
        EXPECT_EQ(answers.at(2), 1.0f) << mode;
    }
}

TEST(Chiba, APartlyCoveringBallShadesByTheOverlapOfTheDiscs)
{
    // unit discs one radius apart overlap in a lens of 2π/3 - √3/2
    auto env = chiba("lens", overhead + "transmittance: 0.5\nestimate intersection area: on\n");
    auto answers = first_params(env->pass({query_at(1, {0, 0, 0}, {1}), query_at(2, {1, 3, 0}, {1})}, 0));
    const double lens = 2 * std::numbers::pi / 3 - std::sqrt(3.0) / 2;
    EXPECT_NEAR(answers.at(1), 1 - 0.5 * lens / std::numbers::pi, 1e-6);
}

TEST(Chiba, EstimatedAreasReachBallsBesideTheRay)
{
    // a small ball whose disc overlaps the receiving disc without touching the ray: area
    // estimation widens each ball's voxels by the largest radius, so the walk finds it
    auto env = chiba("beside", "grid size: 8x8x8\ntransmittance: 0.5\nestimate intersection area: on\n"
                               "source direction: 0 1 0 1\n");
    auto answers = first_params(env->pass({query_at(1, {0, 0, 0}, {1}), query_at(2, {1.1f, 5, 0}, {0.2f})}, 0));
    // the lens of circles of radii 1 and 0.2, 1.1 apart
    const double r1 = 1, r2 = 0.2, d = 1.1;
    const double x1 = (r1 * r1 + d * d - r2 * r2) / (2 * d), x2 = (r2 * r2 + d * d - r1 * r1) / (2 * d);
    const double lens = r1 * r1 * std::acos(x1 / r1) + r2 * r2 * std::acos(x2 / r2) - std::sqrt(r2 * r2 - x2 * x2) * d;
    EXPECT_NEAR(answers.at(1), 1 - 0.5 * lens / std::numbers::pi, 1e-6);
}

TEST(Chiba, FourParametersAlsoGetTheBrightestDirection)
{
    // the light from above is blocked (t = 0); what remains comes from +x
    auto env = chiba("brightest", "grid size: 4x4x4\ntransmittance: 0\nestimate intersection area: on\n"
                                  "source direction: 0 2 0 1\nsource direction: 3 0 0 1\n");
    auto replies = env->pass({query_at(1, {0, 0, 0}, {1, 0, 0, 0}), query_at(2, {0, 3, 0}, {1, 0, 0, 0}),
                              query_at(3, {9, 9, 9}, {1})},
                             0);
    ASSERT_EQ(replies.size(), 3u);
    for (const Reply& r : replies) {
        if (r.address == 1) {
            ASSERT_EQ(r.params.size(), 4u);
            EXPECT_EQ(*r.params[0], 0.5f);
            EXPECT_EQ(*r.params[1], 1.0f);
            EXPECT_EQ(*r.params[2], 0.0f);
            EXPECT_EQ(*r.params[3], 0.0f);
        } else if (r.address == 2) {
            ASSERT_EQ(r.params.size(), 4u);
            EXPECT_EQ(*r.params[0], 1.0f);
            EXPECT_NEAR(*r.params[1], std::sqrt(0.5), 1e-6);
            EXPECT_NEAR(*r.params[2], std::sqrt(0.5), 1e-6);
        } else {
            EXPECT_EQ(r.params.size(), 1u);  // one parameter: the sum only
        }
    }
}

TEST(Chiba, NoPositiveRadiusTakesTheSpecifiedOneAndTwoParametersAreIgnored)
{
    // the ?E(0) ball has the spec's radius 1, so the ball of radius 0.5 above covers a
    // quarter of its disc: 1 - (1 - t) / 4; the ?E with two parameters between them is
    // no ball (it would cover the lowest one fully, a second factor t)
    auto env = chiba("radius", overhead + "radius: 1\ntransmittance: 0.5\nestimate intersection area: on\n");
    auto replies = env->pass({query_at(1, {0, 0, 0}, {0}), query_at(2, {0, 1.5f, 0}, {1, 1}),
                              query_at(3, {0, 3, 0}, {0.5f})},
                             0);
    auto answers = first_params(replies);
    EXPECT_EQ(answers.size(), 2u);
    EXPECT_EQ(answers.at(1), 0.875f);
    EXPECT_EQ(answers.at(3), 1.0f);
}

TEST(Chiba, AWalkAwayFromTheOriginVisitsTheVoxelsTheProgramVisits)
{
    // a ball shades another along the diagonal light; the program's walk places voxel
    // centres as if the grid started at the origin, so moved 100 along x the same pair
    // no longer meets (the models' strings depend on this)
    const std::string spec = "grid size: 8x8x1\ntransmittance: 0.25\nsource direction: 1 1 0 1\n";
    auto at_origin = chiba("walk_origin", spec);
    auto answers = first_params(at_origin->pass({query_at(1, {0.5f, 0.5f, 0.5f}, {0.5f}),
                                                 query_at(2, {3.5f, 3.5f, 0.5f}, {0.5f})},
                                                0));
    EXPECT_NEAR(answers.at(1), 0.25f, 1e-5);
    EXPECT_EQ(answers.at(2), 1.0f);
    auto moved = chiba("walk_moved", spec);
    answers = first_params(moved->pass({query_at(1, {100.5f, 0.5f, 0.5f}, {0.5f}),
                                        query_at(2, {103.5f, 3.5f, 0.5f}, {0.5f})},
                                       0));
    EXPECT_EQ(answers.at(1), 1.0f);
}

TEST(Chiba, TheSkyWeighsTheLowerHalfByTheRatio)
{
    // a huge ball below (t = 0) takes all light from below: 1/(1 + ratio) remains
    const std::string spec = "grid size: 4x4x4\ntransmittance: 0\nestimate intersection area: on\n";
    auto lone = chiba("sky_lone", spec + "lower to upper ratio: 3\n");
    EXPECT_NEAR(first_params(lone->pass({query_at(1, {0, 0, 0}, {1})}, 0)).at(1), 1.0f, 1e-6);
    auto env = chiba("sky_ratio", spec + "lower to upper ratio: 3\nnumber of samples: 128\n");
    auto answers = first_params(env->pass({query_at(1, {0, 0, 0}, {1}), query_at(2, {0, -1002, 0}, {1000})}, 0));
    EXPECT_NEAR(answers.at(1), 0.25f, 1e-6);
    // the CIE overcast sky has nothing below the horizon
    auto cie = chiba("sky_cie", spec + "use CIE formula: yes\n");
    answers = first_params(cie->pass({query_at(1, {0, 0, 0}, {1}), query_at(2, {0, -1002, 0}, {1000})}, 0));
    EXPECT_NEAR(answers.at(1), 1.0f, 1e-6);
}

TEST(Chiba, AnUnlitSkyBelowLeavesTheZenithBrightest)
{
    // the upper samples are symmetric about the vertical
    auto env = chiba("zenith", "lower to upper ratio: 0\nnumber of samples: 20\n");
    auto replies = env->pass({query_at(1, {0, 0, 0}, {1, 0, 0, 0})}, 0);
    ASSERT_EQ(replies.at(0).params.size(), 4u);
    EXPECT_NEAR(*replies[0].params[0], 1.0f, 1e-6);
    EXPECT_NEAR(*replies[0].params[1], 0.0f, 1e-6);
    EXPECT_NEAR(*replies[0].params[2], 1.0f, 1e-6);
    EXPECT_NEAR(*replies[0].params[3], 0.0f, 1e-6);
}

TEST(Chiba, ThreeSpheresAnswerAsTheProgramDid)
{
    // the corpus model 10-light-three-spheres: balls of radius 0.9 one apart up the y
    // axis, one source; cpfg with vlab's chiba wrote these answers (printed with %g)
    auto env = chiba("three_spheres", "grid size: 32x32x32\nverbose: off\ntransmittance: 0.0\n"
                                      "lower to upper ratio: 0.0\nnumber of samples: 128\n"
                                      "estimate intersection area: on\nsource direction:    50 100  0   4\n");
    auto answers = first_params(env->pass({query_at(0, {0, 0, 0}, {0.9f}), query_at(10, {0, 1, 0}, {0.9f}),
                                           query_at(20, {0, 2, 0}, {0.9f})},
                                          0));
    auto g = [](float v) {
        char text[32];
        std::snprintf(text, sizeof text, "%g", v);
        return std::string(text);
    };
    EXPECT_EQ(g(answers.at(0)), "0.189579");
    EXPECT_EQ(g(answers.at(10)), "0.313054");
    EXPECT_EQ(g(answers.at(20)), "1");
}

TEST(Chiba, BadOrOversizedValuesAreErrorsNamingTheLine)
{
    for (const char* spec : {"verbose: off\ngrid size: 300x300x300\n", "verbose: off\ngrid size: 0x4x4\n",
                             "verbose: off\nnumber of samples: 0\n", "verbose: off\ntransmittance: dim\n",
                             "verbose: off\nsource direction: 0 1 0\n"}) {
        try {
            chiba("bad", spec);
            ADD_FAILURE() << "accepted: " << spec;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("light.spec:2"), std::string::npos) << e.what();
        }
    }
}

TEST(Chiba, BallsReachingTooManyVoxelsAreAnError)
{
    // 100 balls at one place each reach all 256^3 voxels: over 2^30 list entries
    auto env = chiba("listed", "grid size: 256x256x256\n");
    std::vector<Query> queries;
    for (std::uint64_t i = 0; i < 100; ++i)
        queries.push_back(query_at(i, {0, 0, 0}, {1}));
    EXPECT_THROW(env->pass(queries, 0), Error);
}

}  // namespace
}  // namespace cambium::env
