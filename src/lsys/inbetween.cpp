// SPDX-License-Identifier: Apache-2.0
// Growth between derivation steps (--inbetween).
#include "lsys/inbetween.h"

#include <stdexcept>

namespace cambium::lsys {
namespace {

/// The first parameter of each module of s.
std::vector<std::size_t> parameter_offsets(const ModuleString& s)
{
    std::vector<std::size_t> offsets(s.size());
    std::size_t offset = 0;
    for (std::size_t i = 0; i < s.size(); ++i) {
        offsets[i] = offset;
        offset += s.param_count(i);
    }
    return offsets;
}

}  // namespace

ModuleString inbetween(const ModuleString& before, const ModuleString& after,
                       std::span<const std::uint32_t> lineage, float t,
                       const std::vector<Growth>& growth)
{
    if (lineage.size() != after.size())
        throw std::invalid_argument("inbetween: the lineage does not match the string");
    std::vector<std::size_t> from = parameter_offsets(before);
    ModuleString out;
    out.reserve(after.size(), after.param_total());
    std::vector<float> params;
    std::size_t offset = 0;
    for (std::size_t i = 0; i < after.size(); ++i) {
        std::size_t n = after.param_count(i);
        const float* target = after.param_data() + offset;
        offset += n;
        params.assign(target, target + n);
        std::uint32_t parent = lineage[i];
        if (parent != no_parent && parent < before.size() && before.param_count(parent) == n) {
            const float* source = before.param_data() + from[parent];
            for (std::size_t k = 0; k < n; ++k)
                params[k] = (1 - t) * source[k] + t * target[k];
        } else if (SymbolId symbol = after.symbol(i);
                   symbol < growth.size() && growth[symbol].from_zero) {
            if (params.empty() && growth[symbol].implied != 0)
                params.push_back(growth[symbol].implied);
            if (!params.empty())
                params[0] *= t;  // the length or width; F(l, o)'s other values are the model's
        }
        out.append(after.symbol(i), params);
    }
    return out;
}

}  // namespace cambium::lsys
