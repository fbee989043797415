// A robot node in C++17 that embeds situ's board (docs/c.md): it loads the
// mower's rules, feeds a stream of sensor events (45 s of a mowing run:
// rain, a bump, a low battery, docking and charging), and prints every
// change of the state from the board's callback with the agents' modes.
//
//   mower_node examples/mower/mower.situ
//
// A ROS 2 node has the same shape: the board is a member, each
// subscription's callback posts, and the change callback publishes.
#include <situ.h>

#include <cstdio>
#include <functional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace situ {

// A failed call: the status and situ's message.
struct Error : std::runtime_error {
    situ_status status;
    explicit Error(situ_status s) : std::runtime_error(situ_last_error()), status(s) {}
};

inline void check(situ_status s) {
    if (s != SITU_OK) throw Error(s);
}

class Program {
   public:
    explicit Program(const std::string &path) { check(situ_program_from_file(path.c_str(), nullptr, 0, &p_)); }
    ~Program() { situ_program_free(p_); }
    Program(const Program &) = delete;
    Program &operator=(const Program &) = delete;
    const situ_program *get() const { return p_; }

   private:
    situ_program *p_ = nullptr;
};

class Board {
   public:
    using OnChange = std::function<void(const situ_change &)>;

    Board(const Program &program, situ_clock clock) { check(situ_board_new(program.get(), clock, &b_)); }
    ~Board() { situ_board_free(b_); }
    Board(const Board &) = delete;
    Board &operator=(const Board &) = delete;

    // The callback runs on the posting thread, with the board unlocked.
    void on_change(OnChange f) {
        on_change_ = std::move(f);
        check(situ_board_on_change(b_, &Board::trampoline, this));
    }

    uint32_t event(const char *name) const {
        uint32_t id = 0;
        check(situ_board_event(b_, name, &id));
        return id;
    }

    // The fast path: an event id and its values in field order.
    situ_posted post(uint32_t event, std::initializer_list<situ_value> values, uint64_t at) {
        situ_posted posted;
        check(situ_board_post_values(b_, event, values.begin(), values.size(), at, &posted));
        return posted;
    }

    std::string state() const {
        const char *s = nullptr;
        check(situ_board_state(b_, &s));
        return s;
    }

    // "Name mode[/function]" for every agent now.
    std::vector<std::string> agents() const {
        situ_agents *view = nullptr;
        check(situ_board_agents(b_, &view));
        size_t n = 0;
        situ_agents_count(view, &n);
        std::vector<std::string> out;
        for (size_t i = 0; i < n; i++) {
            situ_agent a;
            situ_agents_get(view, i, &a);
            const char *mode = a.mode == SITU_RUNNING ? "running" : a.mode == SITU_WAITING ? "waiting" : "sleeping";
            out.push_back(std::string(a.name) + " " + mode + (a.function ? std::string("/") + a.function : ""));
        }
        situ_agents_free(view);
        return out;
    }

    situ_counters counters() const {
        situ_counters c;
        check(situ_board_counters(b_, &c));
        return c;
    }

   private:
    static void trampoline(const situ_change *change, void *self) noexcept {
        try {
            static_cast<Board *>(self)->on_change_(*change);
        } catch (const std::exception &e) {
            std::fprintf(stderr, "the change callback failed: %s\n", e.what());
        }
    }

    situ_board *b_ = nullptr;
    OnChange on_change_;
};

}  // namespace situ

int main(int argc, char **argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: mower_node RULES (examples/mower/mower.situ)\n");
        return 2;
    }
    try {
        situ::Program program(argv[1]);
        situ::Board board(program, SITU_CLOCK_MANUAL);
        board.on_change([&board](const situ_change &c) {
            std::printf("%7.3f s  %s -> %s  (%s)\n", c.time / 1e9, c.from, c.to, c.rule_count ? c.rules[0] : "");
            std::string line = "         ";
            for (const auto &a : board.agents()) line += " " + a;
            std::printf("%s\n", line.c_str());
        });

        const uint32_t gpfix = board.event("GPFIX"), batt = board.event("BATT"), docked = board.event("DOCKED"),
                       rain = board.event("RAIN"), dry = board.event("DRY"), bphit = board.event("BPHIT"),
                       bpfree = board.event("BPFREE"), arrived = board.event("ARRIVED");
        const uint64_t ms = 1000000;
        double charge = 40.0;
        std::printf("%7.3f s  %s\n", 0.0, board.state().c_str());
        for (uint64_t t = 0; t <= 45000; t += 50) {
            const uint64_t at = t * ms;
            if (t % 100 == 0) board.post(gpfix, {situ_f64(0.05)}, at);
            // 14 s: the bumper is pressed, then free four times.
            if (t == 14000) board.post(bphit, {situ_symbol("front")}, at);
            if (t > 14000 && t <= 14200) board.post(bpfree, {}, at);
            if (t % 1000 == 0) {
                // 5 to 7 s: rain; then dry every second.
                if (t >= 5000 && t <= 7000)
                    board.post(rain, {situ_f64(3.0)}, at);
                else if (t > 7000)
                    board.post(dry, {}, at);
                charge += board.state() == "CHARGING" ? 10.0 : -1.0;
                board.post(batt, {situ_f64(charge)}, at + 10 * ms);
            }
            // 30 s: at the station and on its contacts.
            if (t == 30000) {
                board.post(arrived, {}, at);
                board.post(docked, {}, at + 20 * ms);
            }
        }
        situ_counters c = board.counters();
        std::printf("end: %s; %llu events taken, %llu changes, %llu not taken (sleeping)\n", board.state().c_str(),
                    (unsigned long long)c.accepted, (unsigned long long)c.changes,
                    (unsigned long long)c.sleeping);
    } catch (const situ::Error &e) {
        std::fprintf(stderr, "situ: %s (%s)\n", e.what(), situ_status_name(e.status));
        return 1;
    }
    return 0;
}
