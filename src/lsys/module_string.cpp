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
    m_symbols.reserve(modules);
    m_counts.reserve(modules);
    m_params.reserve(params);
}

void ModuleString::clear()
{
    m_symbols.clear();
    m_counts.clear();
    m_params.clear();
}

void ModuleString::append(SymbolId symbol, std::span<const float> params)
{
    if (params.size() > max_params)
        throw Error("a module has " + std::to_string(params.size()) +
                    " parameters; at most 255 are allowed");
    m_symbols.push_back(symbol);
    m_counts.push_back(static_cast<std::uint8_t>(params.size()));
    m_params.insert(m_params.end(), params.begin(), params.end());
}

void ModuleString::append(const ModuleString& other)
{
    m_symbols.insert(m_symbols.end(), other.m_symbols.begin(), other.m_symbols.end());
    m_counts.insert(m_counts.end(), other.m_counts.begin(), other.m_counts.end());
    m_params.insert(m_params.end(), other.m_params.begin(), other.m_params.end());
}

std::size_t ModuleString::memory_bytes() const
{
    return m_symbols.capacity() * sizeof(SymbolId) + m_counts.capacity() +
           m_params.capacity() * sizeof(float);
}

ModuleRef ModuleString::Cursor::operator*() const
{
    std::size_t n = m_string->m_counts[m_index];
    return ModuleRef{m_string->m_symbols[m_index],
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
