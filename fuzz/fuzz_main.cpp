// SPDX-License-Identifier: Apache-2.0
// Set-up shared by every fuzz target (libFuzzer calls it once before the inputs).
#include "base/diagnostics.h"

extern "C" int LLVMFuzzerInitialize(int*, char***)
{
    // warnings are remembered to print each once: millions of distinct ones would only
    // grow that memory and flood the terminal
    cambium::set_warnings_enabled(false);
    return 0;
}
