// SPDX-License-Identifier: Apache-2.0
// Queries and model folders for the environments' tests.
#pragma once

#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "base/scratch.h"
#include "env/builtins.h"

namespace cambium::env::testing {

/// A model folder holding `file` with `text`, as a Context.
inline Context model_with(const std::string& test, const std::string& file, const std::string& text)
{
    Context context;
    context.folder = cambium::testing::scratch("env_" + test);
    std::ofstream(context.folder / file) << text;
    return context;
}

/// A ?E query at `position` (all three components sent) with parameters `params`.
inline Query query_at(std::uint64_t address, std::array<float, 3> position, std::vector<float> params)
{
    Query q;
    q.address = address;
    q.module = SentModule{"?E", std::move(params)};
    q.position = SentVector{position, 3};
    return q;
}

/// The first parameter of each reply, by address.
inline std::map<std::uint64_t, float> first_params(const std::vector<Reply>& replies)
{
    std::map<std::uint64_t, float> out;
    for (const Reply& r : replies)
        if (!r.params.empty() && r.params[0])
            out[r.address] = *r.params[0];
    return out;
}

}  // namespace cambium::env::testing
