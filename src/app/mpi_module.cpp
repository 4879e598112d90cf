// SPDX-License-Identifier: Apache-2.0
// libcambium_mpi.so: MPI calls behind the C interface of app/mpi_module.h. Kept this
// small so that Open MPI is linked into nothing else (docs/distributed.md).
#include "app/mpi_module.h"

#include <mpi.h>

#include <algorithm>
#include <cstdio>
#include <cstring>

namespace {

/// MPI's text for `code` into `error`; returns the code.
int fail(int code, const char* what, char* error, size_t error_size)
{
    char text[MPI_MAX_ERROR_STRING] = {};
    int length = 0;
    if (MPI_Error_string(code, text, &length) != MPI_SUCCESS)
        std::snprintf(text, sizeof text, "MPI error %d", code);
    if (error && error_size > 0)
        std::snprintf(error, error_size, "%s: %s", what, text);
    return code;
}

/// The largest piece sent at once: MPI counts are ints.
constexpr uint64_t piece_bytes = uint64_t{1} << 30;

}  // namespace

extern "C" {

__attribute__((visibility("default"))) int cambium_mpi_interface_version() { return cambium_mpi_version; }

__attribute__((visibility("default"))) int cambium_mpi_init(int* argc, char*** argv, int* rank,
                                                            int* size, char* error,
                                                            size_t error_size)
{
    int provided = 0;
    int code = MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided);
    if (code != MPI_SUCCESS)
        return fail(code, "MPI_Init_thread", error, error_size);
    // Errors come back as codes, so that the caller can say what failed and abort.
    MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
    MPI_Comm_rank(MPI_COMM_WORLD, rank);
    MPI_Comm_size(MPI_COMM_WORLD, size);
    return 0;
}

__attribute__((visibility("default"))) int cambium_mpi_finalize() { return MPI_Finalize(); }

__attribute__((visibility("default"))) void cambium_mpi_abort(int code)
{
    MPI_Abort(MPI_COMM_WORLD, code);
}

__attribute__((visibility("default"))) int cambium_mpi_send(const void* data, uint64_t bytes,
                                                            int to, int tag, char* error,
                                                            size_t error_size)
{
    int code = MPI_Send(&bytes, 1, MPI_UINT64_T, to, tag, MPI_COMM_WORLD);
    if (code != MPI_SUCCESS)
        return fail(code, "MPI_Send", error, error_size);
    const char* p = static_cast<const char*>(data);
    for (uint64_t done = 0; done < bytes;) {
        uint64_t n = std::min(piece_bytes, bytes - done);
        code = MPI_Send(p + done, int(n), MPI_BYTE, to, tag, MPI_COMM_WORLD);
        if (code != MPI_SUCCESS)
            return fail(code, "MPI_Send", error, error_size);
        done += n;
    }
    return 0;
}

__attribute__((visibility("default"))) int cambium_mpi_receive(
    int from, int tag, void* (*allocate)(void*, uint64_t), void* context, char* error,
    size_t error_size)
{
    uint64_t bytes = 0;
    int code = MPI_Recv(&bytes, 1, MPI_UINT64_T, from, tag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    if (code != MPI_SUCCESS)
        return fail(code, "MPI_Recv", error, error_size);
    char* p = static_cast<char*>(allocate(context, bytes));
    for (uint64_t done = 0; done < bytes;) {
        uint64_t n = std::min(piece_bytes, bytes - done);
        code = MPI_Recv(p + done, int(n), MPI_BYTE, from, tag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        if (code != MPI_SUCCESS)
            return fail(code, "MPI_Recv", error, error_size);
        done += n;
    }
    return 0;
}

__attribute__((visibility("default"))) int cambium_mpi_probe(int wait, int* found, int* from,
                                                             int* tag, char* error,
                                                             size_t error_size)
{
    MPI_Status status;
    int code = wait ? MPI_Probe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &status)
                    : MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, found, &status);
    if (code != MPI_SUCCESS)
        return fail(code, wait ? "MPI_Probe" : "MPI_Iprobe", error, error_size);
    if (wait)
        *found = 1;
    if (*found) {
        *from = status.MPI_SOURCE;
        *tag = status.MPI_TAG;
    }
    return 0;
}

__attribute__((visibility("default"))) int cambium_mpi_all_min(int value, int* result,
                                                               char* error, size_t error_size)
{
    int code = MPI_Allreduce(&value, result, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    return code == MPI_SUCCESS ? 0 : fail(code, "MPI_Allreduce", error, error_size);
}
}
