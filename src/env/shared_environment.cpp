// SPDX-License-Identifier: Apache-2.0
#include "env/shared_environment.h"

#include <algorithm>

namespace cambium::env {
namespace {

/// Addresses of different plants kept apart in one pass: the plant's number above them.
constexpr int plant_shift = 40;
constexpr std::uint64_t address_mask = (std::uint64_t{1} << plant_shift) - 1;

class Participant final : public Environment {
public:
    Participant(SharedEnvironment& shared, std::size_t index) : m_shared(shared), m_index(index) {}
    std::vector<Reply> pass(const std::vector<Query>& queries, int step) override
    {
        return m_shared.exchange(m_index, queries, step);
    }
    void idle(int step) override { m_shared.exchange(m_index, {}, step); }
    void observe(const PassPlant& plant) override { m_shared.observe(m_index, plant); }

private:
    SharedEnvironment& m_shared;
    std::size_t m_index;
};

}  // namespace

SharedEnvironment::SharedEnvironment(std::unique_ptr<Environment> environment, std::size_t participants)
    : m_environment(std::move(environment)), m_active(participants), m_queries(participants),
      m_replies(participants), m_left(participants, 0)
{
}

std::unique_ptr<Environment> SharedEnvironment::participant(std::size_t index)
{
    return std::make_unique<Participant>(*this, index);
}

std::vector<Reply> SharedEnvironment::exchange(std::size_t index, const std::vector<Query>& queries, int step)
{
    std::unique_lock lock(m_mutex);
    if (m_failure)
        throw Error(*m_failure);
    std::vector<Query>& mine = m_queries[index];
    mine = queries;
    for (Query& q : mine) {
        q.address = (std::uint64_t(index) << plant_shift) | (q.address & address_mask);
        q.plant = index;
    }
    m_step = std::max(m_step, step);
    const std::size_t round = m_round;
    if (++m_sent == m_active)
        complete_round();
    else
        m_done.wait(lock, [&] { return m_round != round || m_failure; });
    if (m_failure)
        throw Error(*m_failure);
    std::vector<Reply> answers = std::move(m_replies[index]);
    m_replies[index].clear();
    return answers;
}

void SharedEnvironment::observe(std::size_t index, const PassPlant& plant)
{
    PassPlant numbered = plant;
    numbered.plant = index;
    m_environment->observe(numbered);
}

void SharedEnvironment::leave(std::size_t index)
{
    std::lock_guard lock(m_mutex);
    if (m_left[index])
        return;
    m_left[index] = 1;
    --m_active;
    if (m_sent > 0 && m_sent == m_active && !m_failure)
        complete_round();
}

void SharedEnvironment::abandon(const std::string& why)
{
    std::lock_guard lock(m_mutex);
    if (!m_failure)
        m_failure = why;
    m_done.notify_all();
}

void SharedEnvironment::complete_round()
{
    std::vector<Query> all;
    for (std::vector<Query>& q : m_queries) {
        std::move(q.begin(), q.end(), std::back_inserter(all));
        q.clear();
    }
    try {
        // as for one plant: a step without any ?E is not sent
        std::vector<Reply> replies = all.empty() ? std::vector<Reply>{} : m_environment->pass(all, m_step);
        for (Reply& r : replies) {
            const std::size_t plant = std::size_t(r.address >> plant_shift);
            if (plant >= m_replies.size())
                continue;
            r.address &= address_mask;
            m_replies[plant].push_back(std::move(r));
        }
    } catch (const std::exception& e) {
        m_failure = e.what();
    }
    m_sent = 0;
    m_step = 0;
    ++m_round;
    m_done.notify_all();
}

}  // namespace cambium::env
