// SPDX-License-Identifier: Apache-2.0
// The L-system string: interned module symbols and a compact structure-of-arrays store.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <new>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <unordered_map>
#include <utility>
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

namespace detail {

/// Blocks for PodArray: small ones from malloc; from mapped_block_bytes on (Linux)
/// mapped directly, so that growing one moves its pages with mremap instead of copying
/// them into fresh pages that fault in again. Replaces `block` (`old_bytes` long, as the
/// last call returned; `used` of them kept) by one of at least `new_bytes` and returns
/// its size. Throws std::bad_alloc, leaving `block` as it was, when the system refuses
/// or `new_bytes` is more than max_block_bytes.
std::size_t grow_block(void*& block, std::size_t old_bytes, std::size_t used,
                       std::size_t new_bytes);
void free_block(void* block, std::size_t bytes);
/// The largest block grow_block gives (so that no size computation on one overflows).
inline constexpr std::size_t max_block_bytes = std::size_t{1} << (sizeof(std::size_t) * 8 - 2);

/// A growable array of trivially copyable values. Unlike std::vector, growing keeps the
/// block's pages (realloc or mremap, no fresh copy to fault in) and clear() keeps them
/// too, so the two strings a derivation alternates between are faulted in once.
template <class T>
class PodArray {
    static_assert(std::is_trivially_copyable_v<T>);
    // malloc's blocks are aligned for any standard type (mapped ones for a page)
    static_assert(alignof(T) <= alignof(std::max_align_t));

public:
    PodArray() = default;
    PodArray(const PodArray& other) { assign(other.begin(), other.end()); }
    PodArray(PodArray&& other) noexcept
        : m_data(std::exchange(other.m_data, nullptr)),
          m_size(std::exchange(other.m_size, 0)),
          m_capacity(std::exchange(other.m_capacity, 0)),
          m_bytes(std::exchange(other.m_bytes, 0))
    {
    }
    PodArray& operator=(const PodArray& other)
    {
        if (this != &other)
            assign(other.begin(), other.end());
        return *this;
    }
    PodArray& operator=(PodArray&& other) noexcept
    {
        if (this != &other) {
            release();
            m_data = std::exchange(other.m_data, nullptr);
            m_size = std::exchange(other.m_size, 0);
            m_capacity = std::exchange(other.m_capacity, 0);
            m_bytes = std::exchange(other.m_bytes, 0);
        }
        return *this;
    }
    ~PodArray() { release(); }

    std::size_t size() const { return m_size; }
    std::size_t capacity() const { return m_capacity; }
    /// The most values an array can hold (more throws std::bad_alloc).
    static constexpr std::size_t max_size() { return max_block_bytes / sizeof(T); }
    bool empty() const { return m_size == 0; }
    T* data() { return m_data; }
    const T* data() const { return m_data; }
    T* begin() { return m_data; }
    T* end() { return m_data + m_size; }
    const T* begin() const { return m_data; }
    const T* end() const { return m_data + m_size; }
    T& operator[](std::size_t i) { return m_data[i]; }
    const T& operator[](std::size_t i) const { return m_data[i]; }

    void clear() { m_size = 0; }
    void reserve(std::size_t n)
    {
        if (n > m_capacity)
            regrow(n);
    }
    /// Room for `extra` more values, growing by a quarter (not doubling), so that a string
    /// near the memory budget does not briefly need twice its size.
    void make_room(std::size_t extra)
    {
        if (extra > m_capacity - m_size)
            regrow(grown_capacity(extra));
    }
    std::size_t grown_capacity(std::size_t extra) const
    {
        if (extra > max_size() - m_size)
            return max_size() + 1;  // regrow refuses it
        return std::max(m_size + extra, m_capacity + m_capacity / 4 + 64);
    }
    /// Appends without checking the room (after make_room).
    void push_unchecked(T value) { m_data[m_size++] = value; }
    T* extend_unchecked(std::size_t n)
    {
        T* at = m_data + m_size;
        m_size += n;
        return at;
    }
    void push_back(T value)
    {
        make_room(1);
        push_unchecked(value);
    }
    void append(const T* first, const T* last)
    {
        auto n = static_cast<std::size_t>(last - first);
        if (n == 0)
            return;
        if (first >= m_data && first < m_data + m_size) {  // from itself: survives growth
            auto from = static_cast<std::size_t>(first - m_data);
            make_room(n);
            first = m_data + from;
        } else {
            make_room(n);
        }
        std::memcpy(m_data + m_size, first, n * sizeof(T));
        m_size += n;
    }
    void assign(const T* first, const T* last)
    {
        clear();
        append(first, last);
    }

private:
    void regrow(std::size_t capacity)
    {
        if (capacity > max_size())  // capacity * sizeof(T) would not fit
            throw std::bad_alloc();
        void* block = m_data;
        std::size_t bytes = grow_block(block, m_bytes, m_size * sizeof(T), capacity * sizeof(T));
        m_data = static_cast<T*>(block);
        m_bytes = bytes;
        m_capacity = bytes / sizeof(T);
    }
    void release()
    {
        if (m_data)
            free_block(m_data, m_bytes);
        m_data = nullptr;
        m_size = m_capacity = m_bytes = 0;
    }

    T* m_data = nullptr;
    std::size_t m_size = 0;
    std::size_t m_capacity = 0;
    std::size_t m_bytes = 0;  ///< the block's size as grow_block gave it
};

}  // namespace detail

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
    /// Empties the string and keeps its memory for the next one built in it.
    void clear();
    /// Appends one module. Throws cambium::Error with more than max_params parameters.
    void append(SymbolId symbol, std::span<const float> params = {})
    {
        float* to = append_module(symbol, params.size());
        if (!params.empty())
            std::memcpy(to, params.data(), params.size() * sizeof(float));
    }
    /// Appends a module with `count` parameters and returns where the caller writes their
    /// values (valid until the string next grows). Throws cambium::Error past max_params.
    float* append_module(SymbolId symbol, std::size_t count)
    {
        if (count > max_params || (symbol > 0xff && !m_wide))
            return append_module_slow(symbol, count);
        if (m_wide) {
            m_symbols16.push_back(symbol);
        } else {
            m_symbols8.push_back(static_cast<std::uint8_t>(symbol));
        }
        m_counts.push_back(static_cast<std::uint8_t>(count));
        m_params.make_room(count);
        return m_params.extend_unchecked(count);
    }
    void append(const ModuleString& other);
    /// Appends modules [first, last) of `other`, whose parameters start at `param_offset`.
    void append_range(const ModuleString& other, std::size_t first, std::size_t last,
                      std::size_t param_offset);
    /// The same when the caller knows that those modules have `param_count` parameters.
    void append_range(const ModuleString& other, std::size_t first, std::size_t last,
                      std::size_t param_offset, std::size_t param_count);

    std::size_t size() const { return m_counts.size(); }
    bool empty() const { return m_counts.empty(); }
    std::size_t param_total() const { return m_params.size(); }
    SymbolId symbol(std::size_t i) const { return m_wide ? m_symbols16[i] : m_symbols8[i]; }
    /// All parameter values, module after module (index with a prefix sum of counts).
    const float* param_data() const { return m_params.data(); }
    /// The same, writable (a query pass fills ?P ?H ?L ?U values in place).
    std::span<float> mutable_params() { return {m_params.data(), m_params.size()}; }
    std::size_t param_count(std::size_t i) const { return m_counts[i]; }
    /// The parameter counts of all modules, in order.
    const std::uint8_t* count_data() const { return m_counts.data(); }
    /// The symbols of all modules while every id fits in a byte, else nullptr.
    const std::uint8_t* narrow_symbol_data() const { return m_wide ? nullptr : m_symbols8.data(); }
    /// Bytes held by the string's arrays (for memory reports).
    std::size_t memory_bytes() const
    {
        return m_symbols8.capacity() + m_symbols16.capacity() * sizeof(SymbolId) +
               m_counts.capacity() + m_params.capacity() * sizeof(float);
    }
    /// memory_bytes() plus the block that appending one more module would allocate
    /// while the full one is still held: what the string takes at its next peak.
    std::size_t peak_bytes() const
    {
        auto next_block = [](const auto& v, std::size_t extra) -> std::size_t {
            return v.size() + extra > v.capacity() ? v.grown_capacity(extra) * sizeof(v[0]) : 0;
        };
        return memory_bytes() +
               (m_wide ? next_block(m_symbols16, 1) : next_block(m_symbols8, 1)) +
               next_block(m_counts, 1) + next_block(m_params, max_params);
    }

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
    float* append_module_slow(SymbolId symbol, std::size_t count);
    void widen();

    bool m_wide = false;                       ///< symbols stored in m_symbols16
    detail::PodArray<std::uint8_t> m_symbols8;  ///< while every id is below 256
    detail::PodArray<SymbolId> m_symbols16;
    detail::PodArray<std::uint8_t> m_counts;
    detail::PodArray<float> m_params;
};

/// The most characters format_parameter writes ("-1.17549e-38" is 12).
inline constexpr std::size_t max_parameter_chars = 16;

/// Writes `value` at `out` as C's printf "%g" writes it (cpfg's string output), about
/// ten times faster than snprintf; returns the end of the text.
char* format_parameter(char* out, float value);

/// Formats a string as cpfg's text string output does (section 6.3): modules
/// concatenated, parameters in parentheses printed with %g.
std::string to_text(const ModuleString& s, const SymbolTable& symbols);

}  // namespace cambium::lsys
