// SPDX-License-Identifier: Apache-2.0
// Query modules ?P ?H ?L ?U (manual 5.1.9): the turtle's state written back into the string.
#include "geom/query.h"

#include <algorithm>

namespace cambium::geom {

void answer_queries(lsys::ModuleString& string, const lsys::SymbolTable& symbols,
                    const ViewFile& view)
{
    std::vector<QueryAnswer> answers = collect_query_answers(string, symbols, view);
    if (answers.empty())
        return;
    // ModuleString has no writable parameters: rebuild it with the answers in place.
    lsys::ModuleString result;
    result.reserve(string.size(), string.param_total());
    std::size_t next = 0, index = 0;
    std::vector<float> params;
    string.for_each([&](lsys::ModuleRef m) {
        params.assign(m.params.begin(), m.params.end());
        if (next < answers.size() && answers[next].module == index) {
            std::size_t n = std::min<std::size_t>(params.size(), 3);
            std::copy_n(answers[next].values.begin(), n, params.begin());
            ++next;
        }
        result.append(m.symbol, params);
        ++index;
    });
    string = std::move(result);
}

}  // namespace cambium::geom
