// SPDX-License-Identifier: Apache-2.0
// Function files (.func, both versions) and function sets (.fset), evaluated as func().
#include "fuzz_input.h"
#include "geom/function.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    using namespace cambium;
    std::string_view text = fuzz::text_of(data, size);
    return fuzz::run(size, [&] {
        std::vector<geom::SplineFunction> functions;
        if (text.starts_with("funcgalleryver"))
            functions = geom::parse_function_set_text(text, "fuzz.fset");
        else
            functions.push_back(geom::parse_function_text(text, "fuzz.func", 100, "fuzz"));
        for (const geom::SplineFunction& f : functions)
            for (double x : {-1.0, 0.0, 0.3, 0.5, 1.0, 2.0})
                f.evaluate(x);
    });
}
