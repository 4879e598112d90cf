// SPDX-License-Identifier: Apache-2.0
// Denormal floats flushed to zero on the threads that trace rays, as Embree asks: its
// traversal and intersection kernels can slow down badly on denormal operands.
#pragma once

#include <tbb/task_arena.h>
#include <tbb/task_scheduler_observer.h>

#if defined(__x86_64__) || defined(__i386__)
#include <pmmintrin.h>
#include <xmmintrin.h>
#endif

namespace cambium::render {

/// Sets flush-to-zero and denormals-are-zero on the calling thread for its lifetime and
/// restores the thread's previous modes after (no-op off x86). Every thread of a render
/// runs with the same modes, so images stay the same for any thread count.
class DenormalsFlushed {
public:
    DenormalsFlushed()
    {
#if defined(__x86_64__) || defined(__i386__)
        m_ftz = _MM_GET_FLUSH_ZERO_MODE();
        m_daz = _MM_GET_DENORMALS_ZERO_MODE();
        _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
        _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
#endif
    }
    ~DenormalsFlushed()
    {
#if defined(__x86_64__) || defined(__i386__)
        _MM_SET_FLUSH_ZERO_MODE(m_ftz);
        _MM_SET_DENORMALS_ZERO_MODE(m_daz);
#endif
    }
    DenormalsFlushed(const DenormalsFlushed&) = delete;
    DenormalsFlushed& operator=(const DenormalsFlushed&) = delete;

private:
    unsigned m_ftz = 0, m_daz = 0;
};

/// The same on every worker thread that enters `arena` (the thread that calls
/// arena.execute() needs its own DenormalsFlushed).
class ArenaDenormalsFlushed : public tbb::task_scheduler_observer {
public:
    explicit ArenaDenormalsFlushed(tbb::task_arena& arena) : tbb::task_scheduler_observer(arena)
    {
        observe(true);
    }
    ~ArenaDenormalsFlushed() override { observe(false); }

    void on_scheduler_entry(bool /*worker*/) override
    {
#if defined(__x86_64__) || defined(__i386__)
        _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
        _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
#endif
    }
};

}  // namespace cambium::render
