// SPDX-License-Identifier: Apache-2.0
// An environmental program for the tests: the slave side of cpfg's pipe protocol, as a
// program built with vlab's communication library speaks it, written from the protocol.
// Usage: test_program -e FILE.e MODE. It answers the queries of each chunk at the chunk's
// end, or, in `echo`, at once. Modes:
//   echo      ?E(x) with the turtle's x; writes started.txt (its arguments), e-file.txt
//             (the .e it was given) and, at the goodbye, goodbye.txt (the steps it saw)
//             in its working folder
//   nothing   no answers    empty  empty fields (parameters unchanged)
//   unknown   answers to addresses never sent    hang  reads but never answers
//   die       exits with status 3 at the first query   flood  blank lines, endlessly
//   long      one line without end    garbage  a line that is no answer
//   mute      never sends the start-up byte   bad-start  sends 'X' for it
//   deaf      closes its input before the start-up byte, then waits
//   twice     answers each query twice
//   later     ?E(x) after the pass's last chunk, in chunks of 100 as the library writes
//   polygons  ?E(n, top): the polygons after the query (`interpreted modules:`, between
//             Dbegin and Dend lines) and their highest y (0, 0 without a block)
// Started as `obcheck -e FILE.e OBSTACLES` (its file name obcheck), it is a stand-in for
// the corpus's CelticKnot program, written from FACTS-environment.md's description: the
// obstacles are `x1 y1 x2 y2` segments after a `coordinates:` line; ?E(0) marks where a
// segment starts (no answer), ?E(1) answers 1 when the segment from there to here
// crosses an obstacle, else 0 (and here starts the next segment). It answers at once.
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

namespace {

struct Pending {
    unsigned long address;
    std::size_t params;
    float x, y;
    float first;  ///< the ?E's first parameter
    int polygons = 0;
    float top = -1e30f;  ///< the highest y of their vertices
};

/// obcheck's obstacles and the start of the segment being tested (kept across passes).
struct Obstacles {
    std::vector<std::array<float, 4>> segments;
    float start_x = 0, start_y = 0;

    explicit Obstacles(const char* file)
    {
        std::ifstream in(file);
        std::string line;
        while (std::getline(in, line) && line.rfind("coordinates:", 0) != 0) {
        }
        for (std::array<float, 4> s{}; in >> s[0] >> s[1] >> s[2] >> s[3];)
            segments.push_back(s);
    }

    /// The program's unnormalised side test: each segment's ends lie on both sides of the
    /// other's line, within 0.1.
    bool crosses(float x, float y) const
    {
        auto side = [](float ax, float ay, float bx, float by, float px, float py) {
            return (bx - ax) * (py - ay) - (by - ay) * (px - ax);
        };
        for (const auto& o : segments) {
            const float v11 = side(start_x, start_y, x, y, o[0], o[1]);
            const float v12 = side(start_x, start_y, x, y, o[2], o[3]);
            const float v21 = side(o[0], o[1], o[2], o[3], start_x, start_y);
            const float v22 = side(o[0], o[1], o[2], o[3], x, y);
            if (v11 * v12 <= 0.1f && v21 * v22 <= 0.1f)
                return true;
        }
        return false;
    }
};

/// Turtle lines that follow each query line: one per `turtle ...:` line of the .e file.
int turtle_lines(const char* file)
{
    std::ifstream in(file);
    int n = 0;
    for (std::string line; std::getline(in, line);) n += line.rfind("turtle", 0) == 0;
    return n;
}

void answer(const std::string& mode, const Pending& p)
{
    if (mode == "echo" || mode == "later")
        std::printf("%lu E(%g)\n", p.address, double(p.x));
    else if (mode == "polygons")
        std::printf("%lu E(%d,%g)\n", p.address, p.polygons, p.polygons ? double(p.top) : 0.0);
    else if (mode == "twice")
        std::printf("%lu E(1)\n%lu E(2)\n", p.address, p.address);
    else if (mode == "unknown")
        std::printf("%lu E(7)\n", p.address + 1000000);
    else if (mode == "empty") {
        std::printf("%lu E(", p.address);
        for (std::size_t k = 1; k < p.params; ++k) std::printf(",");
        std::printf(")\n");
    } else if (mode == "garbage")
        std::printf("hello, plant\n");
}

}  // namespace

int main(int argc, char** argv)
{
    if (argc < 4 || std::strcmp(argv[1], "-e") != 0)
        return 2;
    const std::string name = argv[0];
    const bool obcheck = name.size() >= 7 && name.compare(name.size() - 7, 7, "obcheck") == 0;
    const std::string mode = obcheck ? "obcheck" : argv[3];
    std::unique_ptr<Obstacles> obstacles;
    if (obcheck)
        obstacles = std::make_unique<Obstacles>(argv[3]);
    if (mode == "mute") {
        for (int c; (c = std::getchar()) != EOF;) {
        }
        return 0;
    }
    if (mode == "deaf")
        std::fclose(stdin);
    std::fputc(mode == "bad-start" ? 'X' : 1, stdout);
    std::fflush(stdout);
    if (mode == "deaf")
        for (;;) ::pause();
    if (mode == "echo") {
        std::ofstream started("started.txt");
        for (int i = 1; i < argc; ++i) started << argv[i] << (i + 1 < argc ? " " : "\n");
        std::ofstream("e-file.txt") << std::ifstream(argv[2]).rdbuf();
    }
    const int turtle = turtle_lines(argv[2]);
    std::vector<Pending> pending;
    std::string steps;
    char line[1 << 16];
    while (std::fgets(line, sizeof line, stdin)) {
        if (std::strncmp(line, "Control", 7) == 0) {
            int flag = 0, step = 0;
            std::sscanf(line + 8, "%d %d", &flag, &step);
            if (flag & 8) {
                std::printf("Control: 5\n");
                std::fputc(1, stdout);
                std::fflush(stdout);
                if (mode == "echo")
                    std::ofstream("goodbye.txt") << steps;
                return 0;
            }
            if (mode == "hang" || (mode == "later" && !(flag & 4))) {
                if (mode == "later")
                    std::printf("Control: 5\n");  // nothing yet for this chunk
                std::fflush(stdout);
                continue;
            }
            for (std::size_t k = 0; k < pending.size(); ++k) {
                if (mode == "later" && k > 0 && k % 100 == 0)
                    std::printf("Control: 1\n");  // the library's own chunks of 100 answers
                answer(mode, pending[k]);
            }
            pending.clear();
            if (flag & 4)
                steps += std::to_string(step) + "\n";
            std::printf("Control: 5\n");
            std::fflush(stdout);
            continue;
        }
        if (std::strncmp(line, "Dbegin", 6) == 0) {
            // the polygons of the last query's following module, up to Dend
            if (pending.empty())
                return 5;
            Pending& p = pending.back();
            while (std::fgets(line, sizeof line, stdin) && std::strncmp(line, "Dend", 4) != 0) {
                if (std::strncmp(line, "polygon ", 8) != 0)
                    return 6;
                ++p.polygons;
                char* at = line + 8;
                for (int k = 0;; ++k) {
                    char* end = nullptr;
                    const float v = std::strtof(at, &end);
                    if (end == at)
                        break;
                    if (k % 3 == 1)
                        p.top = std::max(p.top, v);
                    at = end;
                }
            }
            continue;
        }
        if (mode == "die")
            return 3;
        if (mode == "flood")
            for (;;) std::fputs("\n\n\n\n\n\n\n\n", stdout);
        if (mode == "long")
            for (;;) std::fputs("xxxxxxxx", stdout);
        Pending p{std::strtoul(line, nullptr, 10), 0, 0, 0, 0};
        const char* e = std::strchr(line, 'E');
        if (e && e[1] == '(') {
            p.params = 1;
            p.first = std::strtof(e + 2, nullptr);
            for (const char* c = e + 2; *c && *c != ')'; ++c) p.params += *c == ',';
        }
        for (int k = 0; k < turtle; ++k) {
            char field[1024];
            if (!std::fgets(field, sizeof field, stdin))
                return 4;
            if (k == 0) {
                const char* colon = std::strchr(field, ':');
                char* end = nullptr;
                p.x = std::strtof(colon ? colon + 1 : field, &end);
                p.y = std::strtof(end, nullptr);
            }
        }
        if (obcheck) {
            if (p.first != 0) {
                const bool hit = obstacles->crosses(p.x, p.y);
                std::printf("%lu E(%d)\n", p.address, hit ? 1 : 0);
                if (!hit) {
                    obstacles->start_x = p.x;
                    obstacles->start_y = p.y;
                }
            } else {
                obstacles->start_x = p.x;
                obstacles->start_y = p.y;
            }
            continue;
        }
        if (mode == "echo")
            answer(mode, p);  // at once: it may write while the plant is still writing
        else
            pending.push_back(p);
    }
    return 0;
}
