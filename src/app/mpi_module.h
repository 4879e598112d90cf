// SPDX-License-Identifier: Apache-2.0
// The C interface of libcambium_mpi.so, the one part of Cambium linked with MPI. The
// command loads it with dlopen only for --mpi (app/distributed.cpp), so a plain run
// never loads Open MPI's libraries. Every function returns 0 on success, else an MPI
// error code, and its message goes to `error` (at most error_size bytes, terminated).
#pragma once

#include <stddef.h>
#include <stdint.h>

extern "C" {

/// The interface's version: the loader refuses a module of another version.
inline constexpr int cambium_mpi_version = 2;

/// cambium_mpi_interface_version(): the version the module was built with.
using cambium_mpi_version_fn = int();
/// MPI_Init_thread (funnelled: only the calling thread talks to MPI); the process's
/// rank and the number of ranks in MPI_COMM_WORLD.
using cambium_mpi_init_fn = int(int* argc, char*** argv, int* rank, int* size, char* error,
                                size_t error_size);
using cambium_mpi_finalize_fn = int();
/// MPI_Abort(MPI_COMM_WORLD, code): ends every rank of the job.
using cambium_mpi_abort_fn = void(int code);
/// Sends `bytes` bytes to rank `to` under `tag` (any size: sent in pieces below 1 GiB).
using cambium_mpi_send_fn = int(const void* data, uint64_t bytes, int to, int tag, char* error,
                                size_t error_size);
/// Receives what cambium_mpi_send sent from rank `from` under `tag`: the size first,
/// then `allocate(context, size)` gives the buffer, then the bytes.
using cambium_mpi_receive_fn = int(int from, int tag, void* (*allocate)(void* context, uint64_t),
                                   void* context, char* error, size_t error_size);
/// Whether a message from any rank under any tag waits (MPI_Iprobe; MPI_Probe, which
/// waits for one, when `wait`): its sender and tag then go to `from` and `tag`.
using cambium_mpi_probe_fn = int(int wait, int* found, int* from, int* tag, char* error,
                                 size_t error_size);
/// MPI_Allreduce(MPI_MIN) of one int over every rank.
using cambium_mpi_all_min_fn = int(int value, int* result, char* error, size_t error_size);
}
