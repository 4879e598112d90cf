// SPDX-License-Identifier: Apache-2.0
// --mpi: one render shared among the ranks of an MPI job (docs/distributed.md). MPI
// itself lives in libcambium_mpi.so (app/mpi_module.h), loaded only when --mpi is given.
#pragma once

#include <cstddef>
#include <functional>
#include <memory>
#include <string>

#include "render/render.h"

namespace cambium::app {

/// The MPI job this process belongs to, through libcambium_mpi.so.
class Mpi {
public:
    /// Loads the module (beside the executable, then in the install's library folder)
    /// and initialises MPI. Throws cambium::Error saying what is missing.
    Mpi(int* argc, char*** argv);
    ~Mpi();  ///< MPI_Finalize
    Mpi(const Mpi&) = delete;
    Mpi& operator=(const Mpi&) = delete;

    int rank() const { return m_rank; }
    int size() const { return m_size; }
    void send(const std::string& bytes, int to, int tag);
    std::string receive(int from, int tag);
    /// Collective: the lowest rank that passes `failed` = true, or size() when none does.
    int lowest_failed(bool failed);
    /// Ends every rank of the job (MPI_Abort).
    [[noreturn]] void abort(int code);

    /// Errors. Every rank calls checkpoint() once its model is ready (loaded, derived,
    /// interpreted), or fail() with its error. Before the checkpoint, fail() joins it: the
    /// lowest failing rank prints its error, so an error every rank meets (a bad model file)
    /// is printed once, and every rank ends with status 1. After it, fail() prints and ends
    /// the job with MPI_Abort: no rank waits for a failed one.
    void checkpoint();
    [[noreturn]] void fail(const std::string& message);

private:
    struct Module;
    std::unique_ptr<Module> m_module;
    int m_rank = 0, m_size = 1;
    bool m_checked = false;
};

/// A still shared among the ranks: rank r renders band r of size() (app/tiles.h) and sends
/// it to rank 0, which returns the whole image; the other ranks return an empty Image.
/// The pixels equal a single process's render bit for bit (RenderSettings::crop).
render::Image render_still(Mpi& mpi, const geom::Scene& scene, render::RenderSettings settings,
                           render::RenderReport* report);

/// A sequence shared among the ranks: the k-th frame to render (0-based, in order) is
/// rendered by rank k % size(); rank 0 writes every frame, in order.
class FrameExchange {
public:
    using Write = std::function<void(std::size_t k, render::Image& image)>;
    explicit FrameExchange(Mpi& mpi) : m_mpi(mpi) {}

    bool renders(std::size_t k) const
    {
        return k % std::size_t(m_mpi.size()) == std::size_t(m_mpi.rank());
    }
    /// Whether this process writes files (rank 0).
    bool writes() const { return m_mpi.rank() == 0; }
    /// Frame k was rendered here: rank 0 writes the other ranks' frames before it, then
    /// it; another rank sends it to rank 0.
    void rendered(std::size_t k, render::Image& image, const Write& write);
    /// Rank 0: receives and writes the other ranks' frames before frame `end` (every one
    /// of them must be rendered: a frame number the sequence reaches).
    void receive_until(std::size_t end, const Write& write);

private:
    Mpi& m_mpi;
    std::size_t m_next = 0;  // rank 0: the next frame to write
};

}  // namespace cambium::app
