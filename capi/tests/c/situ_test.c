/* The C API's test: every call of situ.h, and each bad input answered
 * with its status (capi/tests/c_programs.rs builds it with CMake through
 * find_package(situ) and runs it, also under valgrind).
 *
 *   situ_test DIR
 *
 * DIR holds picker.situ, unsigned.bundle, signed.bundle (signed by the
 * key of trusted.pub), damaged.bundle, trusted.pub. Prints one line per
 * failed check and "N passed, M failed"; exits 1 on any failure. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <situ.h>

#define MS 1000000ull

static int passed, failed;

#define CHECK(cond)                                                         \
    do {                                                                    \
        if (cond) {                                                         \
            passed++;                                                       \
        } else {                                                            \
            failed++;                                                       \
            printf("%s:%d: CHECK(%s) failed; last error: %s\n", __FILE__,  \
                   __LINE__, #cond, situ_last_error());                     \
        }                                                                   \
    } while (0)

/* A call's status is `want`, and the message is there when it failed. */
#define STATUS(call, want)                                                  \
    do {                                                                    \
        situ_status got_ = (call);                                          \
        if (got_ == (want) && situ_last_status() == (want) &&               \
            (got_ == SITU_OK) == (situ_last_error()[0] == '\0')) {          \
            passed++;                                                       \
        } else {                                                            \
            failed++;                                                       \
            printf("%s:%d: %s is %s, not %s; last error: %s\n", __FILE__,  \
                   __LINE__, #call, situ_status_name(got_),                 \
                   situ_status_name(want), situ_last_error());              \
        }                                                                   \
    } while (0)

#define OK(call) STATUS(call, SITU_OK)

static char *path_in(const char *dir, const char *name) {
    size_t n = strlen(dir) + strlen(name) + 2;
    char *p = malloc(n);
    snprintf(p, n, "%s/%s", dir, name);
    return p;
}

static char *read_all(const char *path, size_t *len) {
    FILE *f = fopen(path, "rb");
    if (!f) {
        printf("cannot open %s\n", path);
        exit(2);
    }
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *buf = malloc((size_t)n + 1);
    if (fread(buf, 1, (size_t)n, f) != (size_t)n) exit(2);
    buf[n] = '\0';
    fclose(f);
    if (len) *len = (size_t)n;
    return buf;
}

/* What the callback saw. */
struct seen {
    int changes;
    char from[32], to[32], first_rule[32];
    size_t rule_count;
    char state_in_callback[32];
    situ_board *board;
};

static void on_change(const situ_change *c, void *user) {
    struct seen *s = user;
    s->changes++;
    snprintf(s->from, sizeof s->from, "%s", c->from);
    snprintf(s->to, sizeof s->to, "%s", c->to);
    s->rule_count = c->rule_count;
    snprintf(s->first_rule, sizeof s->first_rule, "%s", c->rule_count ? c->rules[0] : "");
    /* Re-entrant: the board is unlocked during the callback. */
    const char *state = NULL;
    if (s->board && situ_board_state(s->board, &state) == SITU_OK)
        snprintf(s->state_in_callback, sizeof s->state_in_callback, "%s", state);
}

/* A callback whose own call fails: the post that ran it still succeeds,
 * and the last error is then that success's. */
static void fail_inside(const situ_change *c, void *user) {
    (void)c;
    uint32_t id;
    if (situ_board_event((situ_board *)user, "NOPE", &id) != SITU_ERR_UNKNOWN_EVENT) abort();
}

/* A callback that frees the board it was called by. */
static void free_on_change(const situ_change *c, void *user) {
    (void)c;
    situ_board_free((situ_board *)user);
}

static situ_posted post(situ_board *b, const char *event, const situ_arg *args, size_t n, uint64_t at) {
    situ_posted p;
    memset(&p, 0xAB, sizeof p);
    STATUS(situ_board_post(b, event, args, n, at, &p), SITU_OK);
    return p;
}

static const char *state_of(situ_board *b) {
    const char *s = "?";
    OK(situ_board_state(b, &s));
    return s;
}

static void test_programs(const char *dir, situ_program **picker) {
    char *source = path_in(dir, "picker.situ"), *unsigned_b = path_in(dir, "unsigned.bundle"),
         *signed_b = path_in(dir, "signed.bundle"), *damaged = path_in(dir, "damaged.bundle"),
         *key = path_in(dir, "trusted.pub"), *missing = path_in(dir, "missing.bundle");
    const char *keys[] = {key};
    const char *no_key[] = {missing};
    situ_program *p = (situ_program *)0x1;

    OK(situ_program_from_file(source, NULL, 0, picker));
    CHECK(*picker != NULL);
    /* A source is never signed: refused under a trust policy. */
    STATUS(situ_program_from_file(source, keys, 1, &p), SITU_ERR_TRUST);
    CHECK(p == NULL);
    OK(situ_program_from_file(signed_b, keys, 1, &p));
    OK(situ_program_free(p));
    OK(situ_program_from_file(unsigned_b, NULL, 0, &p));
    OK(situ_program_free(p));
    STATUS(situ_program_from_file(unsigned_b, keys, 1, &p), SITU_ERR_TRUST);
    CHECK(strstr(situ_last_error(), "not signed") != NULL);
    STATUS(situ_program_from_file(damaged, NULL, 0, &p), SITU_ERR_BUNDLE);
    STATUS(situ_program_from_file(missing, NULL, 0, &p), SITU_ERR_READ);
    STATUS(situ_program_from_file(signed_b, no_key, 1, &p), SITU_ERR_KEY);

    size_t len;
    char *bytes = read_all(signed_b, &len);
    OK(situ_program_from_bytes((const uint8_t *)bytes, len, keys, 1, &p));
    OK(situ_program_free(p));
    bytes[len / 2] ^= 0x5A; /* damaged in memory */
    STATUS(situ_program_from_bytes((const uint8_t *)bytes, len, NULL, 0, &p), SITU_ERR_BUNDLE);
    STATUS(situ_program_from_bytes(NULL, 10, NULL, 0, &p), SITU_ERR_NULL);
    free(bytes);

    /* Rules with an error: the code and the place. */
    STATUS(situ_program_from_source("bad.situ", "states { A initial }\nrule r { when state == B then A }\n", &p),
           SITU_ERR_RULES);
    CHECK(strstr(situ_last_error(), "bad.situ:2:") != NULL);
    STATUS(situ_program_from_source("x.situ", "\xff\xfe", &p), SITU_ERR_UTF8);
    STATUS(situ_program_from_source(NULL, "states { A initial }", &p), SITU_ERR_NULL);
    STATUS(situ_program_from_source("x.situ", "states { A initial }", NULL), SITU_ERR_NULL);

    free(source), free(unsigned_b), free(signed_b), free(damaged), free(key), free(missing);
}

static void test_posts(situ_program *picker) {
    situ_board *b = NULL;
    struct seen seen = {0};
    STATUS(situ_board_new(picker, 7, &b), SITU_ERR_ARGUMENT);
    CHECK(b == NULL);
    OK(situ_board_new(picker, SITU_CLOCK_MANUAL, &b));
    seen.board = b;
    OK(situ_board_on_change(b, on_change, &seen));
    CHECK(strcmp(state_of(b), "IDLE") == 0);
    bool final = true;
    OK(situ_board_is_final(b, &final));
    CHECK(!final);

    /* Names. */
    uint32_t batt = 0, obst = 0, order = 0;
    OK(situ_board_event(b, "BATT", &batt));
    OK(situ_board_event(b, "Lidar.OBST", &obst));
    OK(situ_board_event(b, "Scanner.ORDER", &order));
    STATUS(situ_board_event(b, "BAT", &batt), SITU_ERR_UNKNOWN_EVENT);
    CHECK(strstr(situ_last_error(), "did you mean `BATT`") != NULL);
    STATUS(situ_board_event(b, "Lidar.BATT", &batt), SITU_ERR_NOT_ITS_AGENT);
    STATUS(situ_board_event(b, "\xc3\x28", &batt), SITU_ERR_UTF8);
    STATUS(situ_board_event(b, NULL, &batt), SITU_ERR_NULL);
    STATUS(situ_board_event(b, "BATT", NULL), SITU_ERR_NULL);
    OK(situ_board_event(b, "BATT", &batt));

    /* Posts by name. */
    situ_arg charge80[] = {{"charge", situ_f64(80.0)}};
    situ_posted p = post(b, "BATT", charge80, 1, 0);
    CHECK(p.taken && !p.changed && p.not_taken == SITU_TAKEN && p.reason[0] == '\0');
    situ_arg item7[] = {{"item", situ_i64(7)}};
    p = post(b, "Scanner.ORDER", item7, 1, 10 * MS);
    CHECK(p.taken && p.changed && !p.cascade);
    CHECK(seen.changes == 1 && strcmp(seen.from, "IDLE") == 0 && strcmp(seen.to, "PICKING") == 0);
    CHECK(seen.rule_count == 1 && strcmp(seen.first_rule, "order") == 0);
    CHECK(strcmp(seen.state_in_callback, "PICKING") == 0);
    CHECK(strcmp(state_of(b), "PICKING") == 0);

    /* Bad payloads: an error, and nothing changed. */
    situ_arg unknown_field[] = {{"distanse", situ_f64(1.0)}, {"side", situ_symbol("left")}};
    STATUS(situ_board_post(b, "OBST", unknown_field, 2, 20 * MS, NULL), SITU_ERR_UNKNOWN_FIELD);
    CHECK(strstr(situ_last_error(), "did you mean `distance`") != NULL);
    situ_arg wrong_type[] = {{"distance", situ_bool(true)}, {"side", situ_symbol("left")}};
    STATUS(situ_board_post(b, "OBST", wrong_type, 2, 20 * MS, NULL), SITU_ERR_FIELD_TYPE);
    situ_arg bad_symbol[] = {{"distance", situ_f64(1.0)}, {"side", situ_symbol("up")}};
    STATUS(situ_board_post(b, "OBST", bad_symbol, 2, 20 * MS, NULL), SITU_ERR_FIELD_TYPE);
    situ_arg missing[] = {{"distance", situ_f64(1.0)}};
    STATUS(situ_board_post(b, "OBST", missing, 1, 20 * MS, NULL), SITU_ERR_MISSING_FIELDS);
    situ_arg twice[] = {{"distance", situ_f64(1.0)}, {"distance", situ_f64(1.0)}, {"side", situ_symbol("left")}};
    STATUS(situ_board_post(b, "OBST", twice, 3, 20 * MS, NULL), SITU_ERR_FIELD_TWICE);
    situ_arg float_for_int[] = {{"item", situ_f64(1.5)}};
    STATUS(situ_board_post(b, "ORDER", float_for_int, 1, 20 * MS, NULL), SITU_ERR_FIELD_TYPE);
    situ_arg bad_kind[] = {{"item", situ_i64(1)}};
    bad_kind[0].value.kind = 99;
    STATUS(situ_board_post(b, "ORDER", bad_kind, 1, 20 * MS, NULL), SITU_ERR_ARGUMENT);
    situ_arg null_symbol[] = {{"distance", situ_f64(1.0)}, {"side", situ_symbol(NULL)}};
    STATUS(situ_board_post(b, "OBST", null_symbol, 2, 20 * MS, NULL), SITU_ERR_NULL);
    situ_arg null_field[] = {{NULL, situ_f64(1.0)}};
    STATUS(situ_board_post(b, "BATT", null_field, 1, 20 * MS, NULL), SITU_ERR_NULL);
    STATUS(situ_board_post(b, "BATT", NULL, 1, 20 * MS, NULL), SITU_ERR_NULL);
    STATUS(situ_board_post(b, "NOPE", NULL, 0, 20 * MS, NULL), SITU_ERR_UNKNOWN_EVENT);

    /* The fast path: ids and values in field order. */
    situ_value far[] = {situ_f64(5.0), situ_symbol("left")};
    situ_posted fast;
    OK(situ_board_post_values(b, obst, far, 2, 30 * MS, &fast));
    CHECK(fast.taken && !fast.changed);
    situ_value three[] = {situ_f64(5.0), situ_symbol("left"), situ_bool(true)};
    STATUS(situ_board_post_values(b, obst, three, 3, 30 * MS, NULL), SITU_ERR_UNKNOWN_FIELD);
    STATUS(situ_board_post_values(b, obst, far, 1, 30 * MS, NULL), SITU_ERR_MISSING_FIELDS);
    situ_value swapped[] = {situ_symbol("left"), situ_f64(5.0)};
    STATUS(situ_board_post_values(b, obst, swapped, 2, 30 * MS, NULL), SITU_ERR_FIELD_TYPE);
    STATUS(situ_board_post_values(b, 9999, NULL, 0, 30 * MS, NULL), SITU_ERR_UNKNOWN_EVENT);

    /* Late (before the lidar's latest): not taken, counted, not an error. */
    OK(situ_board_post_values(b, obst, far, 2, 20 * MS, &fast));
    CHECK(!fast.taken && fast.not_taken == SITU_NOT_TAKEN_OUT_OF_ORDER && strlen(fast.reason) > 0);

    /* Agents now: the arm reaches, from the scanner to the gripper. */
    situ_agents *agents = NULL;
    size_t n = 0;
    OK(situ_board_agents(b, &agents));
    OK(situ_agents_count(agents, &n));
    CHECK(n == 5);
    int found_arm = 0;
    for (size_t i = 0; i < n; i++) {
        situ_agent a;
        OK(situ_agents_get(agents, i, &a));
        if (strcmp(a.name, "Arm") == 0) {
            found_arm = 1;
            CHECK(a.mode == SITU_RUNNING && a.function && strcmp(a.function, "reach") == 0);
            CHECK(a.from_count == 1 && strcmp(a.from[0], "Scanner") == 0);
            CHECK(a.to_count == 1 && strcmp(a.to[0], "Gripper") == 0);
            CHECK(a.fsm_state == NULL);
        }
        if (strcmp(a.name, "Gripper") == 0)
            CHECK(a.mode == SITU_WAITING && a.fsm_state && strcmp(a.fsm_state, "Open") == 0);
    }
    CHECK(found_arm);
    situ_agent past;
    STATUS(situ_agents_get(agents, n, &past), SITU_ERR_ARGUMENT);
    OK(situ_agents_free(agents));
    STATUS(situ_agents_count(agents, &n), SITU_ERR_HANDLE);

    /* Why: the rule, its file and line, the facts it matched. */
    situ_why *why = NULL;
    OK(situ_board_why(b, &why));
    CHECK(why != NULL);
    situ_why_info info;
    OK(situ_why_info_get(why, &info));
    CHECK(strcmp(info.from, "IDLE") == 0 && strcmp(info.to, "PICKING") == 0 && info.firing_count == 1);
    situ_firing f;
    OK(situ_why_firing(why, 0, &f));
    CHECK(strcmp(f.rule, "order") == 0 && f.line == 49 && strstr(f.file, "picker.situ") != NULL);
    CHECK(strncmp(f.text, "rule order", 10) == 0);
    CHECK(f.fact_count == 2 && strcmp(f.facts[0].event, "ORDER") == 0 && strcmp(f.facts[1].event, "BATT") == 0);
    CHECK(f.facts[0].field_count == 1 && strcmp(f.facts[0].fields[0].name, "item") == 0);
    CHECK(f.facts[0].fields[0].value.kind == SITU_I64 && f.facts[0].fields[0].value.i64 == 7);
    STATUS(situ_why_firing(why, 1, &f), SITU_ERR_ARGUMENT);
    OK(situ_why_free(why));

    /* Facts: the lidar's symbol. */
    situ_facts *facts = NULL;
    OK(situ_board_facts(b, &facts));
    OK(situ_facts_count(facts, &n));
    int found_lidar = 0;
    for (size_t i = 0; i < n; i++) {
        situ_fact_now fn;
        OK(situ_facts_get(facts, i, &fn));
        if (strcmp(fn.agent, "Lidar") == 0 && fn.has_fact) {
            found_lidar = 1;
            CHECK(fn.fact.field_count == 2 && fn.fact.fields[1].value.kind == SITU_SYMBOL);
            CHECK(strcmp(fn.fact.fields[1].value.symbol, "left") == 0 && fn.fact.time == 30 * MS);
        }
    }
    CHECK(found_lidar);
    OK(situ_facts_free(facts));

    /* Time passes: the battery goes stale and the board faults. */
    bool changed = true;
    OK(situ_board_advance(b, 2000 * MS, &changed));
    CHECK(!changed);
    OK(situ_board_advance(b, 3500 * MS, &changed));
    CHECK(changed && seen.changes == 2 && strcmp(seen.to, "FAULT") == 0);
    bool faulted = false;
    OK(situ_board_is_final(b, &faulted));
    CHECK(faulted);
    uint64_t now = 0;
    OK(situ_board_now(b, &now));
    CHECK(now == 3500 * MS);

    situ_counters c;
    OK(situ_board_counters(b, &c));
    CHECK(c.accepted == 3 && c.changes == 2 && c.out_of_order == 1 && c.sleeping == 0);
    OK(situ_board_free(b));
}

static void test_nan_and_sleep(situ_program *picker) {
    situ_board *b = NULL;
    OK(situ_board_new(picker, SITU_CLOCK_MANUAL, &b));
    situ_arg nan[] = {{"charge", situ_f64(NAN)}};
    situ_arg item1[] = {{"item", situ_i64(1)}};
    situ_posted p = post(b, "BATT", nan, 1, 0);
    CHECK(p.taken);
    p = post(b, "ORDER", item1, 1, 0);
    CHECK(p.taken && !p.changed);
    CHECK(strcmp(state_of(b), "IDLE") == 0); /* NaN is neither >= 20 nor < 20 */
    situ_facts *facts = NULL;
    size_t n = 0;
    OK(situ_board_facts(b, &facts));
    OK(situ_facts_count(facts, &n));
    int nan_seen = 0;
    for (size_t i = 0; i < n; i++) {
        situ_fact_now fn;
        OK(situ_facts_get(facts, i, &fn));
        if (strcmp(fn.agent, "Battery") == 0) nan_seen = fn.has_fact && isnan(fn.fact.fields[0].value.f64);
    }
    CHECK(nan_seen);
    OK(situ_facts_free(facts));

    /* Charging: the arm sleeps, its event is not taken. */
    situ_arg low[] = {{"charge", situ_f64(10.0)}};
    post(b, "BATT", low, 1, 200 * MS);
    CHECK(strcmp(state_of(b), "CHARGING") == 0);
    p = post(b, "PICKED", NULL, 0, 300 * MS);
    CHECK(!p.taken && p.not_taken == SITU_NOT_TAKEN_SLEEPING);
    CHECK(strstr(p.reason, "`Arm` sleeps in CHARGING") != NULL);
    situ_counters c;
    OK(situ_board_counters(b, &c));
    CHECK(c.sleeping == 1);
    OK(situ_board_free(b));
}

static void test_system_clock(situ_program *picker) {
    situ_board *b = NULL;
    OK(situ_board_new(picker, SITU_CLOCK_SYSTEM, &b));
    OK(situ_board_set_max_skew(b, 1000 * MS));
    situ_arg c50[] = {{"charge", situ_f64(50.0)}};
    situ_posted p = post(b, "BATT", c50, 1, SITU_NOW);
    CHECK(p.taken);
    uint64_t now = 0;
    OK(situ_board_now(b, &now));
    CHECK(now > 1700000000ull * 1000000000ull);
    p = post(b, "BATT", c50, 1, now + 3600000ull * MS);
    CHECK(!p.taken && p.not_taken == SITU_NOT_TAKEN_FROM_THE_FUTURE);
    OK(situ_board_free(b));
}

static void test_reload(const char *dir, situ_program *picker) {
    char *path = path_in(dir, "picker.situ");
    char *text = read_all(path, NULL);
    char *low = strstr(text, "BATT(charge < 20.0)");
    CHECK(low != NULL);
    low[14] = '9'; /* charge < 90.0: the new rules stop picking sooner */
    situ_program *newer = NULL, *other = NULL;
    OK(situ_program_from_source("picker.situ", text, &newer));
    OK(situ_program_from_source("other.situ", "states { A initial }\nagent X sensor { event E }\n", &other));

    situ_board *b = NULL;
    struct seen seen = {0};
    OK(situ_board_new(picker, SITU_CLOCK_MANUAL, &b));
    OK(situ_board_on_change(b, on_change, &seen));
    situ_arg c80[] = {{"charge", situ_f64(80.0)}};
    situ_arg item3[] = {{"item", situ_i64(3)}};
    post(b, "BATT", c80, 1, 0);
    post(b, "ORDER", item3, 1, 0);
    CHECK(strcmp(state_of(b), "PICKING") == 0);
    situ_reloaded r;
    OK(situ_board_reload(b, newer, &r));
    CHECK(r.changed && r.carried >= 1);
    CHECK(strcmp(state_of(b), "CHARGING") == 0 && strcmp(seen.to, "CHARGING") == 0);
    STATUS(situ_board_reload(b, other, &r), SITU_ERR_RELOAD);
    CHECK(strcmp(state_of(b), "CHARGING") == 0);
    /* A program is not a board: a handle of another kind. */
    STATUS(situ_board_reload((situ_board *)newer, newer, &r), SITU_ERR_HANDLE);
    /* A callback removed is not called. */
    OK(situ_board_on_change(b, NULL, NULL));
    situ_arg c95[] = {{"charge", situ_f64(95.0)}};
    situ_posted p = post(b, "BATT", c95, 1, 10 * MS);
    CHECK(p.changed && seen.changes == 2); /* the order and the reload, not this */
    OK(situ_board_free(b));
    OK(situ_program_free(newer));
    OK(situ_program_free(other));
    free(text);
    free(path);
}

static void test_handles(situ_program *picker) {
    situ_board *b = NULL;
    OK(situ_board_new(picker, SITU_CLOCK_MANUAL, &b));
    OK(situ_board_on_change(b, fail_inside, b));
    situ_arg low[] = {{"charge", situ_f64(5.0)}};
    situ_posted charging = post(b, "BATT", low, 1, 0); /* checks SITU_OK and an empty last error */
    CHECK(charging.changed);
    OK(situ_board_free(b));
    OK(situ_board_new(picker, SITU_CLOCK_MANUAL, &b));
    /* A callback that frees its own board: the post returns normally. */
    OK(situ_board_on_change(b, free_on_change, b));
    situ_arg c80[] = {{"charge", situ_f64(80.0)}};
    situ_arg item3[] = {{"item", situ_i64(3)}};
    post(b, "BATT", c80, 1, 0);
    post(b, "ORDER", item3, 1, 0);
    /* Use after free: every call answers SITU_ERR_HANDLE. */
    const char *state = NULL;
    STATUS(situ_board_state(b, &state), SITU_ERR_HANDLE);
    STATUS(situ_board_post(b, "BATT", c80, 1, 0, NULL), SITU_ERR_HANDLE);
    STATUS(situ_board_post_values(b, 0, NULL, 0, 0, NULL), SITU_ERR_HANDLE);
    STATUS(situ_board_free(b), SITU_ERR_HANDLE);
    /* A new board may reuse the slot: the old handle is still dead. */
    situ_board *b2 = NULL;
    OK(situ_board_new(picker, SITU_CLOCK_MANUAL, &b2));
    STATUS(situ_board_state(b, &state), SITU_ERR_HANDLE);
    OK(situ_board_state(b2, &state));
    STATUS(situ_board_state(b2, NULL), SITU_ERR_NULL);
    STATUS(situ_board_state(NULL, &state), SITU_ERR_NULL);
    STATUS(situ_board_state((situ_board *)&state, &state), SITU_ERR_HANDLE);
    OK(situ_board_free(b2));
    OK(situ_board_free(NULL));
    OK(situ_program_free(NULL));
    situ_board *never = NULL;
    STATUS(situ_board_new(NULL, SITU_CLOCK_MANUAL, &never), SITU_ERR_NULL);
    STATUS(situ_board_new(picker, SITU_CLOCK_MANUAL, NULL), SITU_ERR_NULL);
}

int main(int argc, char **argv) {
    if (argc != 2) {
        fprintf(stderr, "usage: situ_test DIR\n");
        return 2;
    }
    CHECK(strlen(situ_version()) > 0);
    CHECK(strcmp(situ_status_name(SITU_ERR_UNKNOWN_EVENT), "unknown-event") == 0);
    CHECK(strcmp(situ_status_name(12345), "?") == 0);
    situ_program *picker = NULL;
    test_programs(argv[1], &picker);
    if (!picker) {
        printf("the picker rules did not load: %s\n", situ_last_error());
        return 1;
    }
    test_posts(picker);
    test_nan_and_sleep(picker);
    test_system_clock(picker);
    test_reload(argv[1], picker);
    test_handles(picker);
    OK(situ_program_free(picker));
    STATUS(situ_program_free(picker), SITU_ERR_HANDLE);
    CHECK(situ_live_handles() == 0);
    printf("%d passed, %d failed\n", passed, failed);
    return failed ? 1 : 0;
}
