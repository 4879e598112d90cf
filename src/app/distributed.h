// SPDX-License-Identifier: Apache-2.0
// --mpi: one render shared among the ranks of an MPI job (docs/distributed.md). MPI
// itself lives in libcambium_mpi.so (app/mpi_module.h), loaded only when --mpi is given.
#pragma once

#include <cstddef>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

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
    /// A message waiting from any rank (MPI_Iprobe); with `wait`, the next one to come.
    struct Message {
        int from = 0, tag = 0;
    };
    std::optional<Message> probe(bool wait);
    /// Rank 0's `bytes` on every rank (rank 0 sends them to each other rank); the other
    /// ranks' own `bytes` are not used.
    std::string from_rank0(const std::string& bytes);
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
/// rendered by rank k % size(); rank 0 writes every frame, in order. Turntables use it:
/// each rank renders its views from one BVH (render::render_views), so its share is
/// known before the first view.
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

/// A sequence shared among the ranks on demand (animations: each frame is its own scene).
/// Every rank walks the frames to render, k = 0, 1, ... in order; rank 0 hands the next
/// frame nobody renders yet to whichever rank asks (a rank asks with its first frame and
/// again with each frame it sends back), takes such frames itself as its walk reaches
/// them, answers the others while it renders (render_serving), and writes every frame in
/// order. Which rank renders a frame changes nothing in its pixels.
class FrameQueue {
public:
    using Write = std::function<void(std::size_t k, render::Image& image)>;
    /// `frames`: the frames to render, at most (a derivation's stop() may end it sooner).
    FrameQueue(Mpi& mpi, std::size_t frames, Write write);

    /// Whether this process writes files (rank 0).
    bool writes() const { return m_mpi.rank() == 0; }
    /// Called by every rank for each frame k in order: whether this rank renders it.
    bool renders(std::size_t k);
    /// Rank 0: runs `render` on another thread, answering the other ranks meanwhile
    /// (MPI stays on this thread). Other ranks: runs it.
    render::Image render_serving(const std::function<render::Image()>& render);
    /// Frame k was rendered here: rank 0 writes it in its turn; another rank sends it to
    /// rank 0 and is given its next frame.
    void rendered(std::size_t k, render::Image image);
    /// After the walk: the other ranks say so; rank 0 waits for them and writes every
    /// frame before `reached` (the frames every rank went through). `complete`: whether
    /// every one of them must have been rendered (false after an interrupt).
    void finish(std::size_t reached, bool complete);

private:
    void serve(bool wait);  // rank 0: answers the messages waiting (with `wait`, one at least)
    void give_next(int rank);
    void write_in_order();
    static constexpr std::size_t none = static_cast<std::size_t>(-1);
    Mpi& m_mpi;
    std::size_t m_frames;
    Write m_write;
    // rank 0
    std::size_t m_next_free = 0, m_next_write = 0;
    std::size_t m_reached = 0;  ///< frames rank 0's own walk has come to: written up to them
    std::vector<std::size_t> m_given;  ///< per rank: the frame it renders now
    std::map<std::size_t, render::Image> m_waiting;  ///< rendered, not yet written
    int m_finished = 0;
    // other ranks
    std::optional<std::size_t> m_mine;  ///< the frame given to this rank (none: no more)
};

}  // namespace cambium::app
