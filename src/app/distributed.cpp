// SPDX-License-Identifier: Apache-2.0
// --mpi: the module loader and the sharing of stills (bands) and sequences (frames).
//
// Every rank loads, derives and interprets the model itself (cheap next to rendering)
// and renders its share; only images travel, as the exact bytes of app/tiles.h.
#include "app/distributed.h"

#include <dlfcn.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <future>
#include <vector>

#include <fmt/format.h>

#include "app/mpi_module.h"
#include "app/tiles.h"
#include "base/diagnostics.h"
#include "base/shared_module.h"

namespace cambium::app {
namespace {

namespace fs = std::filesystem;

constexpr int still_tag = 1;
constexpr int frame_tag = 2;     // a rendered frame (FrameExchange, FrameQueue)
constexpr int request_tag = 3;   // FrameQueue: a rank asks for its first frame
constexpr int give_tag = 4;      // FrameQueue: rank 0 gives a frame (or none)
constexpr int finished_tag = 5;  // FrameQueue: a rank is through the sequence
constexpr int shared_tag = 6;    // Mpi::from_rank0

template <typename F>
F* symbol(const SharedModule& module, const char* name)
{
    return reinterpret_cast<F*>(module.symbol(name, "Cambium's MPI module"));
}

void* grow(void* context, std::uint64_t bytes)
{
    auto* buffer = static_cast<std::string*>(context);
    buffer->resize(bytes);
    return buffer->data();
}

}  // namespace

struct Mpi::Module {
    void* handle = nullptr;
    cambium_mpi_finalize_fn* finalize = nullptr;
    cambium_mpi_abort_fn* abort = nullptr;
    cambium_mpi_send_fn* send = nullptr;
    cambium_mpi_receive_fn* receive = nullptr;
    cambium_mpi_all_min_fn* all_min = nullptr;
    cambium_mpi_probe_fn* probe = nullptr;
    char error[512] = {};
};

Mpi::Mpi(int* argc, char*** argv) : m_module(std::make_unique<Module>())
{
    std::string reasons;
    // Global: Open MPI's own plugins, loaded later, need libmpi's symbols.
    SharedModule loaded = load_module("libcambium_mpi.so", RTLD_NOW | RTLD_GLOBAL, reasons);
    m_module->handle = loaded.handle;
    if (!m_module->handle) {
        std::string places;
        for (const fs::path& candidate : module_candidates("libcambium_mpi.so"))
            places += "\n  " + candidate.lexically_normal().string();
        throw Error(reasons.empty()
                        ? "--mpi: this cambium was built without MPI (libcambium_mpi.so is in "
                          "none of:" + places +
                              "); install libopenmpi-dev and build again (docs/distributed.md)"
                        : "--mpi: the MPI module cannot be loaded (is Open MPI installed? "
                          "apt-get install openmpi-bin):" + reasons);
    }
    auto* version = symbol<cambium_mpi_version_fn>(loaded, "cambium_mpi_interface_version");
    if (version() != cambium_mpi_version)
        throw Error(FileLoc{loaded.file.string()}, "is the MPI module of another Cambium version");
    auto* init = symbol<cambium_mpi_init_fn>(loaded, "cambium_mpi_init");
    Module& m = *m_module;
    m.finalize = symbol<cambium_mpi_finalize_fn>(loaded, "cambium_mpi_finalize");
    m.abort = symbol<cambium_mpi_abort_fn>(loaded, "cambium_mpi_abort");
    m.send = symbol<cambium_mpi_send_fn>(loaded, "cambium_mpi_send");
    m.receive = symbol<cambium_mpi_receive_fn>(loaded, "cambium_mpi_receive");
    m.all_min = symbol<cambium_mpi_all_min_fn>(loaded, "cambium_mpi_all_min");
    m.probe = symbol<cambium_mpi_probe_fn>(loaded, "cambium_mpi_probe");
    if (init(argc, argv, &m_rank, &m_size, m.error, sizeof m.error) != 0)
        throw Error(std::string("--mpi: ") + m.error);
}

Mpi::~Mpi()
{
    if (m_module->finalize)
        m_module->finalize();
    // The module stays loaded: Open MPI does not support being unloaded.
}

void Mpi::send(const std::string& bytes, int to, int tag)
{
    if (m_module->send(bytes.data(), bytes.size(), to, tag, m_module->error,
                       sizeof m_module->error) != 0)
        throw Error(std::string("--mpi: ") + m_module->error);
}

std::string Mpi::receive(int from, int tag)
{
    std::string bytes;
    if (m_module->receive(from, tag, &grow, &bytes, m_module->error, sizeof m_module->error) != 0)
        throw Error(std::string("--mpi: ") + m_module->error);
    return bytes;
}

std::optional<Mpi::Message> Mpi::probe(bool wait)
{
    int found = 0;
    Message m;
    if (m_module->probe(wait ? 1 : 0, &found, &m.from, &m.tag, m_module->error,
                        sizeof m_module->error) != 0)
        throw Error(std::string("--mpi: ") + m_module->error);
    return found ? std::optional<Message>(m) : std::nullopt;
}

std::string Mpi::from_rank0(const std::string& bytes)
{
    if (m_rank != 0)
        return receive(0, shared_tag);
    for (int r = 1; r < m_size; ++r)
        send(bytes, r, shared_tag);
    return bytes;
}

int Mpi::lowest_failed(bool failed)
{
    int lowest = m_size;
    if (m_module->all_min(failed ? m_rank : m_size, &lowest, m_module->error,
                          sizeof m_module->error) != 0)
        throw Error(std::string("--mpi: ") + m_module->error);
    return lowest;
}

void Mpi::abort(int code)
{
    m_module->abort(code);
    std::_Exit(code);  // MPI_Abort does not return; in case it does
}

void Mpi::checkpoint()
{
    if (m_checked)
        return;
    m_checked = true;
    if (lowest_failed(false) < m_size) {
        // Another rank failed and printed why; this one ends quietly.
        m_module->finalize();
        m_module->finalize = nullptr;
        std::exit(1);
    }
}

void Mpi::fail(const std::string& message)
{
    std::string line = m_rank == 0 ? "cambium: " + message + "\n"
                                   : fmt::format("cambium (rank {}): {}\n", m_rank, message);
    if (m_checked) {
        std::fputs(line.c_str(), stderr);
        std::fflush(stderr);
        abort(1);
    }
    m_checked = true;
    if (lowest_failed(true) == m_rank)
        std::fputs(line.c_str(), stderr);
    m_module->finalize();
    m_module->finalize = nullptr;
    std::exit(1);
}

render::Image render_still(Mpi& mpi, const geom::Scene& scene, render::RenderSettings settings,
                           render::RenderReport* report)
{
    const int ranks = mpi.size(), w = settings.width, h = settings.height;
    if (ranks > h)
        throw Error(fmt::format("--mpi: {} ranks for an image of {} rows: give at most one rank "
                                "per row",
                                ranks, h));
    settings.crop = band(mpi.rank(), ranks, w, h);
    Tile mine{mpi.rank(), ranks, w, h, settings.crop, render::render(scene, settings, report)};
    if (mpi.rank() != 0) {
        mpi.send(encode_tile(mine), 0, still_tag);
        return {};
    }
    render::Image whole = blank_image(w, h, settings.aovs, settings.transparent_background);
    paste(whole, mine.image, mine.rect.x, mine.rect.y);
    for (int r = 1; r < ranks; ++r) {
        Tile tile = decode_tile(mpi.receive(r, still_tag), fmt::format("rank {}'s tile", r));
        if (tile.rect != band(r, ranks, w, h))
            throw Error(fmt::format("--mpi: rank {} sent another tile than its own", r));
        paste(whole, tile.image, tile.rect.x, tile.rect.y);
    }
    return whole;
}

void FrameExchange::rendered(std::size_t k, render::Image& image, const Write& write)
{
    if (!writes()) {
        m_mpi.send(encode_tile({int(k), int(k) + 1, image.width, image.height,
                                {0, 0, image.width, image.height}, std::move(image)}),
                   0, frame_tag);
        return;
    }
    receive_until(k, write);
    write(k, image);
    m_next = k + 1;
}

void FrameExchange::receive_until(std::size_t end, const Write& write)
{
    if (!writes())
        return;
    for (; m_next < end; ++m_next) {
        int from = int(m_next % std::size_t(m_mpi.size()));
        if (from == 0)
            throw Error(fmt::format("--mpi: frame {} of rank 0 was not rendered", m_next));
        Tile tile = decode_tile(m_mpi.receive(from, frame_tag),
                                fmt::format("rank {}'s frame", from));
        if (std::size_t(tile.index) != m_next)
            throw Error(fmt::format("--mpi: rank {} sent frame {}, not frame {}", from, tile.index,
                                    m_next));
        write(m_next, tile.image);
    }
}

FrameQueue::FrameQueue(Mpi& mpi, std::size_t frames, Write write)
    : m_mpi(mpi), m_frames(frames), m_write(std::move(write)),
      m_given(std::size_t(mpi.size()), none)
{
}

bool FrameQueue::renders(std::size_t k)
{
    if (writes()) {
        m_reached = k + 1;
        serve(false);
        // Every frame before k was taken by rank 0 as it passed, or given away.
        if (k < m_next_free)
            return false;
        m_next_free = k + 1;
        return true;
    }
    if (!m_mine) {  // the first frame to render: ask for one
        m_mpi.send({}, 0, request_tag);
        m_mine = std::stoull(m_mpi.receive(0, give_tag));
    }
    return k == *m_mine;
}

render::Image FrameQueue::render_serving(const std::function<render::Image()>& render)
{
    if (!writes())
        return render();
    std::future<render::Image> image = std::async(std::launch::async, render);
    while (image.wait_for(std::chrono::milliseconds(2)) != std::future_status::ready)
        serve(false);
    return image.get();
}

void FrameQueue::rendered(std::size_t k, render::Image image)
{
    if (writes()) {
        m_waiting.emplace(k, std::move(image));
        write_in_order();
        return;
    }
    m_mpi.send(encode_tile({int(k), int(k) + 1, image.width, image.height,
                            {0, 0, image.width, image.height}, std::move(image)}),
               0, frame_tag);
    m_mine = std::stoull(m_mpi.receive(0, give_tag));
}

void FrameQueue::finish(std::size_t reached, bool complete)
{
    if (!writes()) {
        m_mpi.send({}, 0, finished_tag);
        return;
    }
    m_reached = std::max(m_reached, reached);
    while (m_finished < m_mpi.size() - 1)
        serve(true);
    write_in_order();
    if (complete && m_next_write < reached)
        throw Error(fmt::format("--mpi: frame {} of the sequence was not rendered", m_next_write));
}

void FrameQueue::serve(bool wait)
{
    for (std::optional<Mpi::Message> m; (m = m_mpi.probe(wait)); wait = false) {
        std::string bytes = m_mpi.receive(m->from, m->tag);
        if (m->tag == finished_tag) {
            ++m_finished;
            continue;
        }
        if (m->tag == frame_tag) {
            Tile tile = decode_tile(bytes, fmt::format("rank {}'s frame", m->from));
            if (std::size_t(tile.index) != m_given[std::size_t(m->from)])
                throw Error(fmt::format("--mpi: rank {} sent frame {}, not the frame it was given",
                                        m->from, tile.index));
            m_waiting.emplace(std::size_t(tile.index), std::move(tile.image));
        } else if (m->tag != request_tag) {
            throw Error(fmt::format("--mpi: an unexpected message (tag {}) from rank {}", m->tag,
                                    m->from));
        }
        give_next(m->from);
        write_in_order();
    }
}

void FrameQueue::give_next(int rank)
{
    std::size_t k = m_next_free < m_frames ? m_next_free++ : none;
    m_given[std::size_t(rank)] = k;
    m_mpi.send(std::to_string(k), rank, give_tag);
}

void FrameQueue::write_in_order()
{
    for (auto it = m_waiting.begin();
         it != m_waiting.end() && it->first == m_next_write && it->first < m_reached;
         it = m_waiting.erase(it), ++m_next_write)
        m_write(it->first, it->second);
}

}  // namespace cambium::app
