// SPDX-License-Identifier: Apache-2.0
// The built-in environments on hand-made cases whose answers follow from what vlab's
// programs compute (docs/environment.md).
#include <gtest/gtest.h>

#include <cmath>

#include "env_fixture.h"

namespace cambium::env {
namespace {

using testing::first_params;
using testing::model_with;
using testing::query_at;

std::unique_ptr<Environment> honda81(const std::string& test, const std::string& spec)
{
    Context context = model_with(test, "density.spec", spec);
    return make_builtin("honda81", {"density.spec"}, context);
}

TEST(Honda81, TheLowerVigorLosesWithinTheRadius)
{
    auto env = honda81("vigor", "radius: 0.5\n3d case: on\n");
    auto answers = first_params(env->pass({query_at(0, {0, 0, 0}, {1}), query_at(7, {0.3f, 0, 0}, {2}),
                                          query_at(9, {5, 0, 0}, {0})},
                                         0));
    EXPECT_EQ(answers.at(0), 0.0f);  // vigor 1 against 2 within 0.5: blocked
    EXPECT_EQ(answers.at(7), 1.0f);  // the stronger one is free
    EXPECT_EQ(answers.at(9), 1.0f);  // far from both
}

TEST(Honda81, EqualVigorAtOnePointBlocksBoth)
{
    auto env = honda81("equal", "radius: 0.01\n3d case: on\n");
    auto answers = first_params(env->pass({query_at(1, {1, 2, 3}, {0}), query_at(2, {1, 2, 3}, {0})}, 4));
    EXPECT_EQ(answers.at(1), 0.0f);
    EXPECT_EQ(answers.at(2), 0.0f);
}

TEST(Honda81, GroupsDoNotMeet)
{
    auto env = honda81("groups", "radius: 1\n3d case: on\n");
    auto answers = first_params(env->pass({query_at(1, {0, 0, 0}, {0, 1}), query_at(2, {0, 0, 0}, {5, 2})}, 0));
    EXPECT_EQ(answers.at(1), 1.0f);
    EXPECT_EQ(answers.at(2), 1.0f);
}

TEST(Honda81, GroupsBeyondIntegersStayApart)
{
    // 3e9 and 4e9 are no int: C's conversion of them is undefined (on x86 both became
    // INT_MIN, one group). They name two groups, which do not meet; NaN names none.
    auto env = honda81("big_groups", "radius: 1\n3d case: on\n");
    auto answers = first_params(env->pass({query_at(1, {0, 0, 0}, {0, 3e9f}), query_at(2, {0, 0, 0}, {5, 4e9f}),
                                          query_at(3, {0, 0, 0}, {0, NAN}), query_at(4, {0, 0, 0}, {1, NAN})},
                                         0));
    EXPECT_EQ(answers.at(1), 1.0f);
    EXPECT_EQ(answers.at(2), 1.0f);
    EXPECT_EQ(answers.at(3), 1.0f);
    EXPECT_EQ(answers.at(4), 1.0f);
    auto same = first_params(env->pass({query_at(1, {0, 0, 0}, {0, 3e9f}), query_at(2, {0, 0, 0}, {5, 3e9f})}, 1));
    EXPECT_EQ(same.at(1), 0.0f);  // one group: the lower vigor is blocked
}

TEST(Honda81, TwoDimensionsCompareXAndZ)
{
    // without "3d case: on" the program measures in (x, z): y differences do not separate
    auto env = honda81("planar", "radius: 0.5\n");
    auto answers = first_params(env->pass({query_at(1, {0, 0, 0}, {1}), query_at(2, {0, 10, 0.2f}, {2}),
                                          query_at(3, {0.2f, 0, 10}, {3})},
                                         0));
    EXPECT_EQ(answers.at(1), 0.0f);
    EXPECT_EQ(answers.at(3), 1.0f);
}

TEST(Honda81, TheRadiusIsInclusive)
{
    auto env = honda81("boundary", "radius: 2\n3d case: on\n");
    auto answers = first_params(env->pass({query_at(1, {0, 0, 0}, {1}), query_at(2, {2, 0, 0}, {2})}, 0));
    EXPECT_EQ(answers.at(1), 0.0f);
}

TEST(Honda81, AQueryWithoutAWholePositionGetsNoAnswer)
{
    auto env = honda81("partial", "radius: 1\n3d case: on\n");
    Query q = query_at(3, {0, 0, 0}, {1});
    q.position.count = 2;
    auto replies = env->pass({q, query_at(4, {0, 0, 0}, {0})}, 0);
    ASSERT_EQ(replies.size(), 1u);
    EXPECT_EQ(replies[0].address, 4u);
    EXPECT_EQ(*replies[0].params[0], 1.0f);  // the query without position does not block
}

TEST(Honda81, ManyPointsOnAGridAnswerAsAllPairs)
{
    // the spatial grid must find exactly the pairs the program's all-pairs loop finds
    auto env = honda81("grid", "radius: 0.75\n3d case: on\n");
    std::vector<Query> queries;
    for (int i = 0; i < 400; ++i)
        queries.push_back(query_at(static_cast<std::uint64_t>(i),
                                   {static_cast<float>(i % 20) * 0.7f, static_cast<float>(i / 20) * 0.9f,
                                    static_cast<float>((i * 7) % 3)},
                                   {static_cast<float>(i % 5)}));
    auto answers = first_params(env->pass(queries, 0));
    for (std::size_t i = 0; i < queries.size(); ++i) {
        bool blocked = false;
        for (std::size_t j = 0; j < queries.size(); ++j) {
            if (i == j || queries[i].module.params[0] > queries[j].module.params[0])
                continue;
            float d2 = 0;
            for (int k = 0; k < 3; ++k) {
                float e = queries[i].position.values[k] - queries[j].position.values[k];
                d2 += e * e;
            }
            blocked |= d2 <= 0.75f * 0.75f;
        }
        EXPECT_EQ(answers.at(i), blocked ? 0.0f : 1.0f) << "query " << i;
    }
}

TEST(Honda81, AMissingSpecificationFileIsAnError)
{
    Context context = model_with("missing", "other.txt", "");
    EXPECT_THROW(make_builtin("honda81", {"density.spec"}, context), Error);
    EXPECT_THROW(make_builtin("honda81", {}, context), Error);
}

TEST(Honda81, ASpecificationFileOutsideTheFolderIsRefused)
{
    Context context = model_with("outside", "density.spec", "radius: 1\n");
    Context other = model_with("outside_other", "x", "");
    EXPECT_THROW(make_builtin("honda81", {(context.folder / "density.spec").string()}, other), Error);
    other.allow_file_access = true;
    EXPECT_NE(make_builtin("honda81", {(context.folder / "density.spec").string()}, other), nullptr);
}

std::unique_ptr<Environment> ecosystem(const std::string& test, const std::string& spec)
{
    Context context = model_with(test, "density.spec", spec);
    return make_builtin("./ecosystem", {"-x", "density.spec"}, context);
}

TEST(Ecosystem, ASmallerIntersectingCircleIsDominated)
{
    auto env = ecosystem("size", "grid size: 10 10 10\nvigor: off\n");
    auto answers = first_params(env->pass({query_at(1, {0, 5, 0}, {1}), query_at(2, {2.5f, -5, 0}, {2}),
                                          query_at(3, {10, 0, 0}, {1})},
                                         0));
    EXPECT_EQ(answers.at(1), 0.0f);  // radius 1 reaches radius 2 at distance 2.5 (in x, z)
    EXPECT_EQ(answers.at(2), 1.0f);
    EXPECT_EQ(answers.at(3), 1.0f);
}

TEST(Ecosystem, GroupsBeyondIntegersStayApart)
{
    auto env = ecosystem("big_groups", "vigor: off\n");
    auto answers = first_params(env->pass({query_at(1, {0, 0, 0}, {1, 3e9f}), query_at(2, {0, 0, 0}, {2, 4e9f})}, 0));
    EXPECT_EQ(answers.at(1), 1.0f);  // groups 3e9 and 4e9 do not meet
    EXPECT_EQ(answers.at(2), 1.0f);
    auto same = first_params(env->pass({query_at(1, {0, 0, 0}, {1, 3e9f}), query_at(2, {0, 0, 0}, {2, 3e9f})}, 1));
    EXPECT_EQ(same.at(1), 0.0f);  // one group: the smaller circle is dominated
}

TEST(Ecosystem, TheKeywordIsCaseSensitiveSoCapitalThreeDStaysPlanar)
{
    auto env = ecosystem("case", "3D case: on\n");
    auto answers = first_params(env->pass({query_at(1, {0, 0, 0}, {1}), query_at(2, {0, 100, 0}, {1})}, 0));
    EXPECT_EQ(answers.at(1), 0.0f);  // planar: y is ignored, so they meet
    auto env3 = ecosystem("case3", "3d case: yes\n");
    auto answers3 = first_params(env3->pass({query_at(1, {0, 0, 0}, {1}), query_at(2, {0, 100, 0}, {1})}, 0));
    EXPECT_EQ(answers3.at(1), 1.0f);
}

TEST(Ecosystem, WithVigorARemovedCircleNoLongerDominates)
{
    // a (vigor 1) loses to b (vigor 2); b loses to c (vigor 3); c does not reach a.
    // In string order b is removed before a is tested only if b comes first.
    auto env = ecosystem("vigor", "vigor: on\n");
    auto answers = first_params(env->pass({query_at(1, {1.5f, 0, 0}, {1, 2}), query_at(2, {3, 0, 0}, {1, 3}),
                                          query_at(3, {0, 0, 0}, {1, 1})},
                                         0));
    EXPECT_EQ(answers.at(1), 0.0f);  // b: dominated by c
    EXPECT_EQ(answers.at(2), 1.0f);  // c: free
    EXPECT_EQ(answers.at(3), 1.0f);  // a: its only dominator b was removed before it
}

TEST(Builtins, UnknownProgramsHaveNoBuiltIn)
{
    Context context;
    EXPECT_EQ(make_builtin("obcheck", {}, context), nullptr);
}

}  // namespace
}  // namespace cambium::env
