// SPDX-License-Identifier: Apache-2.0
// The L-system string: interned module symbols and a compact structure-of-arrays store.
#include "lsys/module_string.h"

#include <cstdio>

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
    m_symbols16.assign(m_symbols8.begin(), m_symbols8.end());
    m_symbols16.reserve(m_symbols8.capacity());
    std::vector<std::uint8_t>().swap(m_symbols8);
    m_wide = true;
}

void ModuleString::append(SymbolId symbol, std::span<const float> params)
{
    if (params.size() > max_params)
        throw Error("a module has " + std::to_string(params.size()) +
                    " parameters; at most 255 are allowed");
    if (symbol > 0xff && !m_wide)
        widen();
    if (m_wide) {
        make_room(m_symbols16, 1);
        m_symbols16.push_back(symbol);
    } else {
        make_room(m_symbols8, 1);
        m_symbols8.push_back(static_cast<std::uint8_t>(symbol));
    }
    make_room(m_counts, 1);
    m_counts.push_back(static_cast<std::uint8_t>(params.size()));
    if (!params.empty()) {
        make_room(m_params, params.size());
        m_params.insert(m_params.end(), params.begin(), params.end());
    }
}

void ModuleString::append(const ModuleString& other)
{
    append_range(other, 0, other.size(), 0);
}

void ModuleString::append_range(const ModuleString& other, std::size_t first, std::size_t last,
                                std::size_t param_offset)
{
    if (first >= last)
        return;
    std::size_t n = last - first;
    if (other.m_wide && !m_wide)
        widen();
    if (m_wide) {
        make_room(m_symbols16, n);
        for (std::size_t i = first; i < last; ++i)
            m_symbols16.push_back(other.symbol(i));
    } else {
        make_room(m_symbols8, n);
        m_symbols8.insert(m_symbols8.end(), other.m_symbols8.begin() + static_cast<std::ptrdiff_t>(first),
                          other.m_symbols8.begin() + static_cast<std::ptrdiff_t>(last));
    }
    make_room(m_counts, n);
    auto counts = other.m_counts.begin();
    m_counts.insert(m_counts.end(), counts + static_cast<std::ptrdiff_t>(first),
                    counts + static_cast<std::ptrdiff_t>(last));
    std::size_t params = 0;
    for (std::size_t i = first; i < last; ++i)
        params += other.m_counts[i];
    if (params) {
        make_room(m_params, params);
        auto values = other.m_params.begin() + static_cast<std::ptrdiff_t>(param_offset);
        m_params.insert(m_params.end(), values, values + static_cast<std::ptrdiff_t>(params));
    }
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

std::string to_text(const ModuleString& s, const SymbolTable& symbols)
{
    std::string out;
    char buf[64];
    s.for_each([&](ModuleRef m) {
        out += symbols.name(m.symbol);
        if (m.params.empty())
            return;
        out += '(';
        for (std::size_t i = 0; i < m.params.size(); ++i) {
            std::snprintf(buf, sizeof buf, "%g", static_cast<double>(m.params[i]));
            if (i)
                out += ',';
            out += buf;
        }
        out += ')';
    });
    return out;
}

}  // namespace cambium::lsys
