// SPDX-License-Identifier: Apache-2.0
// The L-system string: interned module symbols and a compact structure-of-arrays store.
#pragma once

#include <algorithm>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

namespace cambium::lsys {

/// Interned module name ("F", "@Gs", "?P", "~l"...).
using SymbolId = std::uint16_t;

/// Maps module names to dense ids and back. Ids are stable for the table's lifetime.
class SymbolTable {
public:
    /// The id of `name`, adding it when new. Throws cambium::Error past 65535 symbols.
    SymbolId intern(std::string_view name);
    /// The id of `name`, or -1 when the name was never interned.
    int find(std::string_view name) const;
    std::string_view name(SymbolId id) const { return m_names[id]; }
    std::size_t size() const { return m_names.size(); }

private:
    std::vector<std::string> m_names;
    std::unordered_map<std::string, SymbolId> m_ids;
};

/// One module as seen through a ModuleString: its symbol and parameter values.
struct ModuleRef {
    SymbolId symbol;
    std::span<const float> params;
};

/// A string of modules. Parameters are 32-bit floats, as cpfg stores them.
///
/// Storage is three flat arrays (symbol, parameter count, parameter values): two bytes
/// per module plus four per parameter while every symbol id fits in a byte (the array
/// widens to 16 bits the first time one does not), no per-module heap object. Walk it
/// with a Cursor, which tracks the parameter offset in both directions.
class ModuleString {
public:
    static constexpr std::size_t max_params = 255;

    void reserve(std::size_t modules, std::size_t params);
    void clear();
    /// Appends one module. Throws cambium::Error with more than max_params parameters.
    void append(SymbolId symbol, std::span<const float> params = {});
    void append(const ModuleString& other);
    /// Appends modules [first, last) of `other`, whose parameters start at `param_offset`.
    void append_range(const ModuleString& other, std::size_t first, std::size_t last,
                      std::size_t param_offset);

    std::size_t size() const { return m_counts.size(); }
    bool empty() const { return m_counts.empty(); }
    std::size_t param_total() const { return m_params.size(); }
    SymbolId symbol(std::size_t i) const { return m_wide ? m_symbols16[i] : m_symbols8[i]; }
    /// All parameter values, module after module (index with a prefix sum of counts).
    const float* param_data() const { return m_params.data(); }
    /// The same, writable (a query pass fills ?P ?H ?L ?U values in place).
    std::span<float> mutable_params() { return m_params; }
    std::size_t param_count(std::size_t i) const { return m_counts[i]; }

    /// A position in the string that knows where its module's parameters start.
    class Cursor {
    public:
        Cursor() = default;
        std::size_t index() const { return m_index; }
        /// Index of the module's first parameter in param_data() / mutable_params().
        std::size_t param_offset() const { return m_offset; }
        bool at_end() const { return m_index >= m_string->size(); }
        ModuleRef operator*() const;
        void next();
        void prev();  // precondition: index() > 0

    private:
        friend class ModuleString;
        Cursor(const ModuleString* s, std::size_t index, std::size_t offset)
            : m_string(s), m_index(index), m_offset(offset) {}
        const ModuleString* m_string = nullptr;
        std::size_t m_index = 0;
        std::size_t m_offset = 0;
    };

    Cursor begin() const { return Cursor(this, 0, 0); }
    Cursor end() const { return Cursor(this, size(), m_params.size()); }

    /// Calls f(ModuleRef) for every module in order.
    template <class F>
    void for_each(F&& f) const
    {
        std::size_t offset = 0;
        for (std::size_t i = 0; i < m_counts.size(); ++i) {
            std::size_t n = m_counts[i];
            f(ModuleRef{symbol(i), std::span<const float>(m_params.data() + offset, n)});
            offset += n;
        }
    }

private:
    void widen();
    /// Grows `v` by a quarter instead of doubling, so that a string near the memory
    /// budget does not briefly need twice its size.
    template <class T>
    static void make_room(std::vector<T>& v, std::size_t extra)
    {
        if (v.size() + extra > v.capacity())
            v.reserve(std::max(v.size() + extra, v.capacity() + v.capacity() / 4 + 64));
    }

    bool m_wide = false;                   ///< symbols stored in m_symbols16
    std::vector<std::uint8_t> m_symbols8;  ///< while every id is below 256
    std::vector<SymbolId> m_symbols16;
    std::vector<std::uint8_t> m_counts;
    std::vector<float> m_params;
};

/// Formats a string as cpfg's text string output does (section 6.3): modules
/// concatenated, parameters in parentheses printed with %g.
std::string to_text(const ModuleString& s, const SymbolTable& symbols);

}  // namespace cambium::lsys
