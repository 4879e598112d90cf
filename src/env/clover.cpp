// SPDX-License-Identifier: Apache-2.0
// vlab's clover: light from above on a 2-D grid. Each cell holds the light an image gives
// it (green), a ratio (red) and how many leaves cover it. ?E(1) or ?E(0, ...) asks for the
// light; ?E(1, area) lays a leaf disc of that area over the cells, ?E(other, area) lifts
// one. Discs change the grid as they come, in string order; the light questions are
// answered after the whole pass: green/255 times the transmittance once per leaf. The
// leaves stay from pass to pass, as in the program, which runs once for the whole run.
// Single precision where the program keeps floats, so the answers match its digits.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>

#include "base/input_file.h"
#include "env/builtins.h"
#include "env/spec_values.h"

namespace cambium::env {
namespace {

constexpr int max_side = 4096;  // cells a side: a model file may not ask for more
constexpr std::uintmax_t max_image_file_bytes = std::uintmax_t{1} << 30;  // as environment maps

struct Settings {
    std::array<int, 2> size{512, 512};
    std::array<float, 2> origin{-1, -1};
    std::array<float, 2> extent{2, 2};
    float transmittance = 0.6f;
    std::string image;  ///< empty: full light everywhere
    FileLoc image_loc;  ///< the `input image:` line, for errors about the file it names
    bool remove_old_leaves = false;
    bool z_is_up = true;
};

struct Cell {
    std::uint8_t leaves = 0;
    std::uint8_t light = 255;
    std::uint8_t ratio = 0;
};

class Clover final : public Environment {
public:
    Clover(Settings s, std::vector<Cell> cells) : m_s(std::move(s)), m_cells(std::move(cells))
    {
        // transmittance^n for the 256 possible leaf counts, as the program's table of
        // single-precision products
        m_power[0] = 1.0f;
        for (std::size_t i = 1; i < m_power.size(); ++i)
            m_power[i] = m_s.transmittance * m_power[i - 1];
    }

    std::vector<Reply> pass(const std::vector<Query>& queries, int) override
    {
        if (m_s.remove_old_leaves)
            for (Cell& c : m_cells)
                c.leaves = 0;
        struct Question {
            std::array<float, 2> at;
            std::size_t num_params;
            std::uint64_t address;
        };
        std::vector<Question> questions;
        for (const Query& q : queries) {
            const std::vector<float>& p = q.module.params;
            if (p.empty() || q.position.count < (m_s.z_is_up ? 2 : 3))
                continue;
            // the plane of the ground: (x, y) when z is up, else (x, z)
            const std::array<float, 2> at{q.position.values[0], q.position.values[m_s.z_is_up ? 1 : 2]};
            if (p.size() == 1 || p[0] == 0)
                questions.push_back({at, p.size(), q.address});
            else
                lay_disc(at, p[1], p[0] == 1 ? 1 : -1);
        }
        std::vector<Reply> replies;
        replies.reserve(questions.size());
        for (const Question& q : questions) {
            const Cell* c = cell_at(q.at);
            Reply r{q.address, {c ? static_cast<float>(static_cast<float>(c->light) / 255.0 * m_power[c->leaves])
                                  : 0.0f}};
            if (q.num_params >= 2)
                r.params.emplace_back(c ? static_cast<float>(static_cast<float>(c->ratio) / 128.0) : 0.0f);
            replies.push_back(std::move(r));
        }
        return replies;
    }

private:
    /// The cell of a point on axis `a`, as the program floors it in single precision,
    /// kept within a range that cannot overflow (far points stay off the grid).
    std::int64_t node(float v, int a) const
    {
        const double n = std::floor((v - m_s.origin[a]) / m_s.extent[a] * static_cast<float>(m_s.size[a]));
        if (!(n == n))
            return -limit;
        return static_cast<std::int64_t>(std::clamp(n, -static_cast<double>(limit), static_cast<double>(limit)));
    }

    const Cell* cell_at(const std::array<float, 2>& at) const
    {
        const std::int64_t x = node(at[0], 0), y = node(at[1], 1);
        if (x < 0 || y < 0 || x >= m_s.size[0] || y >= m_s.size[1])
            return nullptr;
        return &m_cells[static_cast<std::size_t>(y * m_s.size[0] + x)];
    }

    /// Adds (+1) or removes (-1) a leaf disc of `area` centred at `at`: the cells of an
    /// ellipse of floor(r / extent · size) + 1 cells a half-axis around the centre's cell,
    /// the half-open range [-h, h) the program loops over. Counts stay within 0..255.
    void lay_disc(const std::array<float, 2>& at, float area, int change)
    {
        if (area < 0.0000001)
            return;
        const float radius = static_cast<float>(std::sqrt(area / std::numbers::pi));
        std::array<std::int64_t, 2> centre{}, half{}, from{}, to{};
        for (int a = 0; a < 2; ++a) {
            centre[a] = node(at[a], a);
            const double h = radius / m_s.extent[a] * static_cast<float>(m_s.size[a]) + 1;
            if (!(h == h))
                return;
            half[a] = static_cast<std::int64_t>(std::clamp(h, 0.0, static_cast<double>(limit)));
            // only the offsets that land on the grid: the others change nothing
            from[a] = std::max(-half[a], -centre[a]);
            to[a] = std::min(half[a], m_s.size[a] - centre[a]);
        }
        const float hx2 = static_cast<float>(half[0] * half[0]), hy2 = static_cast<float>(half[1] * half[1]);
        for (std::int64_t y = from[1]; y < to[1]; ++y)
            for (std::int64_t x = from[0]; x < to[0]; ++x) {
                if (!(static_cast<float>(x * x) / hx2 + static_cast<float>(y * y) / hy2 <= 1))
                    continue;
                Cell& c = m_cells[static_cast<std::size_t>((centre[1] + y) * m_s.size[0] + centre[0] + x)];
                if (change > 0 && c.leaves < 255)
                    ++c.leaves;
                else if (change < 0 && c.leaves > 0)
                    --c.leaves;
            }
    }

    /// Far enough that no cell beyond it is on a grid, near enough that x² fits 64 bits.
    static constexpr std::int64_t limit = std::int64_t{1} << 31;

    Settings m_s;
    std::vector<Cell> m_cells;  ///< row by row, from the grid's lowest y up
    std::array<float, 256> m_power{};
};

/// The grid's cells from the image: cell (x, y) takes the pixel at (x·(w-1)/(size-1),
/// y·(h-1)/(size-1)), each product truncated, with image rows counted from the bottom
/// (the program reads SGI images, whose first row is the bottom one).
std::vector<Cell> cells_from(const Settings& s, const Context& context)
{
    std::vector<Cell> cells(static_cast<std::size_t>(s.size[0]) * static_cast<std::size_t>(s.size[1]));
    if (s.image.empty())
        return cells;  // the program's full light where no image is named
    if (!context.read_image)
        throw Error("clover: cannot read the input image " + s.image + ": no image reader");
    const std::filesystem::path file = model_file(s.image, context);
    // a FIFO or device would block the image reader forever: regular files only, sized first
    try {
        regular_file_size(file, "the input image", max_image_file_bytes);
    } catch (const Error& e) {
        const std::string why = e.what();
        const std::size_t at = why.find("error: ");
        throw Error(s.image_loc, "clover: input image " + file.string() + ": " +
                                     (at == std::string::npos ? why : why.substr(at + 7)));
    }
    const RgbImage image = context.read_image(file);
    if (image.width < 1 || image.height < 1 ||
        image.rgb.size() != static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height) * 3)
        throw Error(FileLoc{file.string()}, "clover: the input image is empty or malformed");
    // a one-cell side has no spacing: it takes the first pixel
    auto ratio = [](int pixels, int side) {
        return side > 1 ? static_cast<float>(pixels - 1) / static_cast<float>(side - 1) : 0.0f;
    };
    const float xratio = ratio(image.width, s.size[0]), yratio = ratio(image.height, s.size[1]);
    for (int y = 0; y < s.size[1]; ++y) {
        const int from_bottom = std::min(static_cast<int>(static_cast<float>(y) * yratio), image.height - 1);
        const std::size_t row = static_cast<std::size_t>(image.height - 1 - from_bottom);
        for (int x = 0; x < s.size[0]; ++x) {
            const int column = std::min(static_cast<int>(static_cast<float>(x) * xratio), image.width - 1);
            const std::size_t pixel = (row * static_cast<std::size_t>(image.width) + static_cast<std::size_t>(column)) * 3;
            Cell& c = cells[static_cast<std::size_t>(y) * static_cast<std::size_t>(s.size[0]) + static_cast<std::size_t>(x)];
            c.ratio = image.rgb[pixel];
            c.light = image.rgb[pixel + 1];
        }
    }
    return cells;
}

}  // namespace

std::unique_ptr<Environment> make_clover(const std::vector<std::string>& args, const Context& context)
{
    Settings s;
    for (const SpecLine& line : read_spec_file(spec_argument("clover", args), context)) {
        const std::string& k = line.keyword;
        if (k == "grid size") {
            const std::vector<double> v = leading_numbers(line, 2);
            for (std::size_t a = 0; a < v.size(); ++a) {
                if (!(v[a] >= 1 && v[a] < max_side + 1))
                    throw Error(line.loc, "clover: grid size: from 1 to " + std::to_string(max_side) +
                                              " cells a side, found '" + line.value + "'");
                s.size[a] = static_cast<int>(v[a]);
            }
        } else if (k == "grid position") {
            const std::vector<double> v = leading_numbers(line, 2);
            for (std::size_t a = 0; a < v.size(); ++a)
                s.origin[a] = static_cast<float>(v[a]);
        } else if (k == "grid range") {
            const std::vector<double> v = leading_numbers(line, 2);
            for (std::size_t a = 0; a < v.size(); ++a) {
                if (!(v[a] > 0))
                    throw Error(line.loc, "clover: grid range: must be positive, found '" + line.value + "'");
                s.extent[a] = static_cast<float>(v[a]);
            }
        } else if (k == "transmittance") {
            s.transmittance = static_cast<float>(number_value(line));
            if (s.transmittance == 0)
                s.transmittance = 0.0001f;  // the program's replacement: zero is not allowed
        } else if (k == "input image") {
            // the file name: up to a blank, comma, semicolon or colon ('x' may be in a name)
            s.image = line.value.substr(0, line.value.find_first_of(" \t,;:"));
            s.image_loc = line.loc;
        } else if (k == "remove old leaves") {
            s.remove_old_leaves = switch_value(line, {"on", "yes"});
        } else if (k == "z is up") {
            s.z_is_up = !switch_value(line, {"no", "off"});
        } else if (k != "verbose") {
            warn_unknown_keyword("clover", line);
        }
    }
    std::vector<Cell> cells = cells_from(s, context);
    return std::make_unique<Clover>(std::move(s), std::move(cells));
}

}  // namespace cambium::env
