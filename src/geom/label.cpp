// SPDX-License-Identifier: Apache-2.0
// `@L` labels: their text, printf-formatted from the module's parameters.
#include "geom/label.h"

#include <cmath>
#include <cstdio>
#include <string_view>
#include <vector>

#include "geom/scene_limits.h"

namespace cambium::geom {

std::optional<std::string> label_text(std::span<const float> params, std::span<const std::string> strings)
{
    std::optional<int> string = params.empty() ? std::nullopt : whole_number(params[0]);
    if (!string || *string < 0 || static_cast<std::size_t>(*string) >= strings.size())
        return std::nullopt;
    return format_label(strings[static_cast<std::size_t>(*string)], params.subspan(1));
}

std::string format_label(const std::string& format, std::span<const float> values)
{
    std::string out;
    std::size_t next = 0;
    for (std::size_t i = 0; i < format.size(); ++i) {
        if (format[i] != '%' || i + 1 >= format.size()) {
            out += format[i];
            continue;
        }
        if (format[i + 1] == '%') {
            out += '%';
            ++i;
            continue;
        }
        // only flags, then a width and a precision of at most 2 digits each (as the
        // L-system's printf), may stand between '%' and the conversion: a longer width
        // would pad a label with up to two billion characters
        std::size_t end = format.find_first_not_of("-+ #0", i + 1);
        auto digits = [&](std::size_t at) {
            std::size_t stop = format.find_first_not_of("0123456789", at);
            return (stop == std::string::npos ? format.size() : stop) - at;
        };
        std::size_t width = end == std::string::npos ? 0 : digits(end);
        std::size_t precision = 0;
        if (end != std::string::npos) {
            end += width;
            if (end < format.size() && format[end] == '.') {
                precision = digits(end + 1);
                end += 1 + precision;
            }
        }
        if (end >= format.size() || end - i > 12 || width > 2 || precision > 2 ||
            std::string_view("diouxXeEfFgG").find(format[end]) == std::string_view::npos) {
            out += format[i];
            continue;
        }
        std::string spec = format.substr(i, end - i + 1);
        double value = next < values.size() ? static_cast<double>(values[next++]) : 0.0;
        char buffer[256];  // 99 digits of precision after 39 of a float's largest value
        char conversion = format[end];
        // an integer conversion of a value no long long holds prints it as %g
        bool integral = std::abs(value) < 9e18;
        if (std::string_view("diouxX").find(conversion) != std::string_view::npos && integral)
            std::snprintf(buffer, sizeof buffer, (spec.substr(0, spec.size() - 1) + "lld").c_str(),
                          static_cast<long long>(value));
        else if (!integral)
            std::snprintf(buffer, sizeof buffer, (spec.substr(0, spec.size() - 1) + "g").c_str(), value);
        else
            std::snprintf(buffer, sizeof buffer, spec.c_str(), value);
        out += buffer;
        i = end;
    }
    return out;
}

}  // namespace cambium::geom
