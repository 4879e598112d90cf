// SPDX-License-Identifier: Apache-2.0
// Specification files of the built-in environments (honda81, ecosystem, chiba, clover):
// each built-in is made from the input as its specification file (clover's light image
// is a fixed 8x8 grey one) and answers one environmental pass of three ?E modules.
#include "env/builtins.h"
#include "fuzz_input.h"

namespace {

using namespace cambium;

std::vector<env::Query> queries()
{
    std::vector<env::Query> q(3);
    for (std::size_t i = 0; i < q.size(); ++i) {
        float x = static_cast<float>(i) * 0.5f;
        q[i].address = i * 64;
        q[i].module = {"?E", {1, 2, 0.5f, 3}};
        q[i].following = env::SentModule{"F", {1}};
        q[i].position = {{x, 1, -x}, 3};
        q[i].heading = {{0, 1, 0}, 3};
        q[i].left = {{-1, 0, 0}, 3};
        q[i].up = {{0, 0, 1}, 3};
        q[i].line_width = {{0.2f, 0, 0}, 1};
        q[i].scale_factor = {{1, 0, 0}, 1};
    }
    return q;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    return fuzz::run(size, [&] {
        fuzz::write_input(data, size, "fuzz.spec");
        env::Context context;
        context.folder = ".";
        context.read_image = [](const std::filesystem::path&) {
            return env::RgbImage{8, 8, std::vector<std::uint8_t>(8 * 8 * 3, 128)};
        };
        for (const char* program : {"honda81", "ecosystem", "chiba", "clover"}) {
            try {
                std::unique_ptr<env::Environment> e =
                    env::make_builtin(program, {"fuzz.spec"}, context);
                e->pass(queries(), 0);
                e->pass(queries(), 1);
            } catch (const Error&) {
            }
        }
    });
}
