// SPDX-License-Identifier: Apache-2.0
// The L-system string: interned module symbols and a compact structure-of-arrays store.
#include "lsys/module_string.h"

#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <new>

#ifdef __linux__
#include <sys/mman.h>
#endif

#include "base/diagnostics.h"

namespace cambium::lsys {

SymbolId SymbolTable::intern(std::string_view name)
{
    auto it = m_ids.find(std::string(name));
    if (it != m_ids.end())
        return it->second;
    if (m_names.size() >= 0xffff)
        throw Error("too many distinct module names (more than 65535)");
    auto id = static_cast<SymbolId>(m_names.size());
    m_names.emplace_back(name);
    m_ids.emplace(std::string(name), id);
    return id;
}

int SymbolTable::find(std::string_view name) const
{
    auto it = m_ids.find(std::string(name));
    return it == m_ids.end() ? -1 : it->second;
}

namespace detail {

namespace {

#ifdef __linux__
/// Blocks from this size on are mapped directly: growing them remaps their pages. (Not
/// asked for transparent huge pages: on a virtual machine that hands freed memory back
/// to its host, a fresh 2 MiB page cost up to 2 ms to fault in, several times the 4 KiB
/// pages it replaces, and its zeroed tail added to the peak; docs/benchmarks.md.)
constexpr std::size_t mapped_block_bytes = std::size_t{256} << 10;
constexpr std::size_t page_bytes = 4096;  // mmap rounds up to the real page size

std::size_t mapped_size(std::size_t bytes)
{
    return (bytes + page_bytes - 1) & ~(page_bytes - 1);
}
#endif

}  // namespace

std::size_t grow_block(void*& block, std::size_t old_bytes, std::size_t used,
                       std::size_t new_bytes)
{
    if (new_bytes > max_block_bytes)
        throw std::bad_alloc();
#ifdef __linux__
    if (new_bytes >= mapped_block_bytes) {
        std::size_t size = mapped_size(new_bytes);
        void* grown = nullptr;
        if (block && old_bytes >= mapped_block_bytes) {
            // The pages move with the mapping: nothing is copied or faulted in again.
            grown = ::mremap(block, old_bytes, size, MREMAP_MAYMOVE);
            if (grown == MAP_FAILED)
                throw std::bad_alloc();
        } else {
            grown = ::mmap(nullptr, size, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS,
                           -1, 0);
            if (grown == MAP_FAILED)
                throw std::bad_alloc();
            if (block) {
                std::memcpy(grown, block, used);
                std::free(block);
            }
        }
        block = grown;
        return size;
    }
#endif
    (void)old_bytes;
    (void)used;
    void* grown = std::realloc(block, new_bytes);
    if (!grown)
        throw std::bad_alloc();
    block = grown;
    return new_bytes;
}

void free_block(void* block, std::size_t bytes)
{
#ifdef __linux__
    if (bytes >= mapped_block_bytes) {
        ::munmap(block, bytes);
        return;
    }
#endif
    (void)bytes;
    std::free(block);
}

}  // namespace detail

void ModuleString::reserve(std::size_t modules, std::size_t params)
{
    if (m_wide)
        m_symbols16.reserve(modules);
    else
        m_symbols8.reserve(modules);
    m_counts.reserve(modules);
    m_params.reserve(params);
}

void ModuleString::clear()
{
    m_symbols8.clear();
    m_symbols16.clear();
    m_counts.clear();
    m_params.clear();
}

void ModuleString::widen()
{
    m_symbols16.reserve(std::max(m_symbols8.capacity(), m_symbols8.size() + 1));
    for (std::uint8_t s : m_symbols8)
        m_symbols16.push_unchecked(s);
    m_symbols8 = detail::PodArray<std::uint8_t>();
    m_wide = true;
}

float* ModuleString::append_module_slow(SymbolId symbol, std::size_t count)
{
    if (count > max_params)
        throw Error("a module has " + std::to_string(count) +
                    " parameters; at most 255 are allowed");
    widen();
    return append_module(symbol, count);
}

void ModuleString::append(const ModuleString& other)
{
    append_range(other, 0, other.size(), 0);
}

void ModuleString::append_range(const ModuleString& other, std::size_t first, std::size_t last,
                                std::size_t param_offset)
{
    std::size_t params = 0;
    for (std::size_t i = first; i < last; ++i)
        params += other.m_counts[i];
    append_range(other, first, last, param_offset, params);
}

void ModuleString::append_range(const ModuleString& other, std::size_t first, std::size_t last,
                                std::size_t param_offset, std::size_t params)
{
    if (first >= last)
        return;
    std::size_t n = last - first;
    if (other.m_wide && !m_wide)
        widen();
    if (m_wide) {
        m_symbols16.make_room(n);
        if (other.m_wide)
            std::memcpy(m_symbols16.extend_unchecked(n), other.m_symbols16.data() + first,
                        n * sizeof(SymbolId));
        else
            for (std::size_t i = first; i < last; ++i)
                m_symbols16.push_unchecked(other.m_symbols8[i]);
    } else {
        m_symbols8.append(other.m_symbols8.data() + first, other.m_symbols8.data() + last);
    }
    const std::uint8_t* counts = other.m_counts.data();
    m_counts.append(counts + first, counts + last);
    const float* values = other.m_params.data() + param_offset;
    m_params.append(values, values + params);
}

ModuleRef ModuleString::Cursor::operator*() const
{
    std::size_t n = m_string->m_counts[m_index];
    return ModuleRef{m_string->symbol(m_index),
                     std::span<const float>(m_string->m_params.data() + m_offset, n)};
}

void ModuleString::Cursor::next()
{
    m_offset += m_string->m_counts[m_index];
    ++m_index;
}

void ModuleString::Cursor::prev()
{
    --m_index;
    m_offset -= m_string->m_counts[m_index];
}

namespace {

/// 10^k for k = 0 .. 12, all exact in a double.
constexpr std::array<double, 13> powers_of_ten = {1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6,
                                                  1e7, 1e8, 1e9, 1e10, 1e11, 1e12};

/// %g of a float from 10^-4 up to 10^6 that is not whole: six significant digits in fixed
/// notation without trailing zeros. A float times 10^k (k <= 12) is exact in a double
/// (24 + 28 bits), so rounding it to an integer rounds the exact value, half to even,
/// as printf does. Returns nullptr where %g would write an exponent instead.
char* format_fixed(char* out, double magnitude)
{
    // the power of ten of the leading digit: 10^e <= magnitude < 10^(e+1)
    int e = magnitude >= 1 ? (magnitude >= 1e3 ? (magnitude >= 1e4 ? (magnitude >= 1e5 ? 5 : 4) : 3)
                                               : (magnitude >= 1e2 ? 2 : magnitude >= 1e1 ? 1 : 0))
                           : -1;
    double scaled = magnitude * powers_of_ten[static_cast<std::size_t>(5 - e)];
    while (scaled < 1e5 && e > -4) {  // below 1, the exact comparison is on the scaled value
        --e;
        scaled = magnitude * powers_of_ten[static_cast<std::size_t>(5 - e)];
    }
    if (scaled < 1e5)
        return nullptr;  // below 10^-4
    auto digits = static_cast<std::uint32_t>(std::nearbyint(scaled));
    if (digits >= 1000000) {  // rounded up into the next power of ten
        digits /= 10;
        if (++e >= 6)
            return nullptr;
    }
    char text[6];
    for (int k = 5; k >= 0; --k, digits /= 10)
        text[k] = static_cast<char>('0' + digits % 10);
    int length = 6;
    while (length > 0 && text[length - 1] == '0')
        --length;
    if (e >= 0) {
        int whole = e + 1;
        for (int k = 0; k < whole; ++k)
            *out++ = text[k];
        if (length > whole) {
            *out++ = '.';
            for (int k = whole; k < length; ++k)
                *out++ = text[k];
        }
        return out;
    }
    *out++ = '0';
    *out++ = '.';
    for (int k = -1; k > e; --k)
        *out++ = '0';
    for (int k = 0; k < length; ++k)
        *out++ = text[k];
    return out;
}

}  // namespace

char* format_parameter(char* out, float value)
{
    char* end = out + max_parameter_chars;
    const float magnitude = std::abs(value);
    // Whole numbers below 10^6 are what %g prints them as: their digits (and "-0").
    if (magnitude < 1e6f && value == std::trunc(value)) {
        if (std::signbit(value))
            *out++ = '-';
        return std::to_chars(out, end, static_cast<long>(magnitude)).ptr;
    }
    if (!std::isfinite(value))
        return out + std::snprintf(out, max_parameter_chars, "%g", static_cast<double>(value));
    if (magnitude >= 1e-4f && magnitude < 1e6f) {
        bool negative = std::signbit(value);
        if (char* fixed = format_fixed(negative ? out + 1 : out, static_cast<double>(magnitude))) {
            if (negative)
                *out = '-';
            return fixed;
        }
    }
    // The precision overload is specified as printf's %.6g, which is %g.
    return std::to_chars(out, end, static_cast<double>(value), std::chars_format::general, 6).ptr;
}

std::string to_text(const ModuleString& s, const SymbolTable& symbols)
{
    std::string out;
    char buf[max_parameter_chars];
    s.for_each([&](ModuleRef m) {
        out += symbols.name(m.symbol);
        if (m.params.empty())
            return;
        out += '(';
        for (std::size_t i = 0; i < m.params.size(); ++i) {
            if (i)
                out += ',';
            out.append(buf, format_parameter(buf, m.params[i]));
        }
        out += ')';
    });
    return out;
}

}  // namespace cambium::lsys
