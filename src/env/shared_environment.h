// SPDX-License-Identifier: Apache-2.0
// One environment for several plants (a scene file's field of open L-systems): each
// plant derives in a thread of its own, and at every step their ?E modules, in world
// coordinates, go to the environment together, so the plants compete for space or light.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "env/environment.h"

namespace cambium::env {

class SharedEnvironment {
public:
    /// `environment` answers the plants numbered 0 to participants - 1.
    SharedEnvironment(std::unique_ptr<Environment> environment, std::size_t participants);

    /// Plant `index`'s view of the environment: its pass() blocks until every plant still
    /// deriving has sent this step's queries (or idled), then returns its own answers.
    std::unique_ptr<Environment> participant(std::size_t index);

    /// Plant `index` derives no more: later steps go on without it. Called once per plant,
    /// also when its derivation failed.
    void leave(std::size_t index);

    /// A plant failed: every waiting and later exchange throws an Error saying so.
    void abandon(const std::string& why);

    /// Plant `index`'s pass, shown to the environment (from the plant's own thread, without
    /// the lock: the environment's observe() is made for it).
    void observe(std::size_t index, const PassPlant& plant);

    /// One plant's queries (addresses its own) for `step`; its answers.
    std::vector<Reply> exchange(std::size_t index, const std::vector<Query>& queries, int step);

private:
    /// Runs the pass once every active plant has sent (under the lock).
    void complete_round();

    std::unique_ptr<Environment> m_environment;
    std::mutex m_mutex;
    std::condition_variable m_done;
    std::size_t m_active;
    std::size_t m_sent = 0;
    std::size_t m_round = 0;
    int m_step = 0;
    std::vector<std::vector<Query>> m_queries;
    std::vector<std::vector<Reply>> m_replies;
    std::vector<char> m_left;
    std::optional<std::string> m_failure;
};

}  // namespace cambium::env
