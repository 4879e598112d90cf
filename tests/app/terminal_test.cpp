// SPDX-License-Identifier: Apache-2.0
// The command's terminal: the progress line's text and the Ctrl-C flag.
#include <gtest/gtest.h>

#include <csignal>

#include "app/terminal.h"

namespace cambium::app {
namespace {

TEST(Terminal, InterruptHandlerSetsTheFlag)
{
    const std::atomic<bool>* flag = install_interrupt_handler();
    ASSERT_NE(flag, nullptr);
    EXPECT_EQ(install_interrupt_handler(), flag);
    EXPECT_FALSE(flag->load());
    std::raise(SIGINT);
    EXPECT_TRUE(flag->load());
    std::signal(SIGINT, SIG_DFL);
}

TEST(Terminal, ProgressLineFormat)
{
    EXPECT_EQ(format_progress(0.42, 12), "render 42%  elapsed 0:12  remaining 0:17");
    EXPECT_EQ(format_progress(0.5, 3700), "render 50%  elapsed 1:01:40  remaining 1:01:40");
    EXPECT_EQ(format_progress(0, 5), "render 0%  elapsed 0:05  remaining ?");
    EXPECT_EQ(format_progress(1, 65), "render 100%  elapsed 1:05  remaining 0:00");
}

}  // namespace
}  // namespace cambium::app
