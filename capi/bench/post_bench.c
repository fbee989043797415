/* The C API's cost per event: a stream file (as `situ bench --stream-out`
 * or capi/examples/post_bench.rs writes it) posted through
 * situ_board_post_values, the fast path (docs/performance.md).
 *
 *   post_bench RULES STREAM
 *
 * Two passes, as `situ bench` makes them: throughput (only the posts are
 * timed) and latency (each post timed alone with clock_gettime; the
 * clock's own cost is printed beside). A board in a final state is made
 * anew, untimed, before the next event, as `situ bench` resets its
 * engine. Prints one line of JSON. */
#define _POSIX_C_SOURCE 200809L
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <situ.h>

struct event {
    uint32_t id;
    uint64_t time;
    size_t first, count; /* values[first .. first + count] */
};

static situ_value *values;
static size_t n_values, cap_values;
static struct event *events;
static size_t n_events, cap_events;
static char **names; /* symbols and event names, freed at the end */
static size_t n_names, cap_names;

static void die(const char *what) {
    fprintf(stderr, "post_bench: %s: %s\n", what, situ_last_error());
    exit(1);
}

static char *keep(const char *s) {
    if (n_names == cap_names) names = realloc(names, (cap_names = cap_names * 2 + 64) * sizeof *names);
    return names[n_names++] = strdup(s);
}

static situ_value parse_value(const char *w) {
    if (strcmp(w, "true") == 0) return situ_bool(true);
    if (strcmp(w, "false") == 0) return situ_bool(false);
    char *end;
    long long i = strtoll(w, &end, 10);
    if (*end == '\0') return situ_i64(i);
    double x = strtod(w, &end);
    if (*end == '\0') return situ_f64(x);
    return situ_symbol(keep(w));
}

static void read_stream(situ_board *b, const char *path) {
    FILE *f = fopen(path, "r");
    if (!f) {
        perror(path);
        exit(1);
    }
    char *line = NULL;
    size_t cap = 0;
    while (getline(&line, &cap, f) > 0) {
        char *save, *w = strtok_r(line, " \t\n", &save);
        if (!w || w[0] == '#') continue;
        if (n_events == cap_events) events = realloc(events, (cap_events = cap_events * 2 + 1024) * sizeof *events);
        struct event *e = &events[n_events++];
        e->time = strtoull(w, NULL, 10);
        const char *name = strtok_r(NULL, " \t\n", &save);
        if (!name || situ_board_event(b, name, &e->id) != SITU_OK) die("an event of the stream");
        e->first = n_values;
        e->count = 0;
        while ((w = strtok_r(NULL, " \t\n", &save)) && w[0] != '@') {
            if (n_values == cap_values) values = realloc(values, (cap_values = cap_values * 2 + 4096) * sizeof *values);
            values[n_values++] = parse_value(w);
            e->count++;
        }
    }
    free(line);
    fclose(f);
}

static uint64_t now_ns(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (uint64_t)t.tv_sec * 1000000000u + (uint64_t)t.tv_nsec;
}

static int cmp_u64(const void *a, const void *b) {
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

static situ_board *fresh(situ_program *p, situ_board *old) {
    situ_board *b = NULL;
    if (old) situ_board_free(old);
    if (situ_board_new(p, SITU_CLOCK_MANUAL, &b) != SITU_OK) die("a board");
    return b;
}

/* Posts event i; makes the board anew (untimed by the caller) when it is final. */
static int post(situ_board *b, size_t i, uint64_t *changes) {
    const struct event *e = &events[i];
    situ_posted p;
    if (situ_board_post_values(b, e->id, values + e->first, e->count, e->time, &p) != SITU_OK) die("a post");
    if (!p.changed) return 0;
    (*changes)++;
    bool final = false;
    situ_board_is_final(b, &final);
    return final;
}

int main(int argc, char **argv) {
    if (argc != 3) {
        fprintf(stderr, "usage: post_bench RULES STREAM\n");
        return 2;
    }
    situ_program *program = NULL;
    if (situ_program_from_file(argv[1], NULL, 0, &program) != SITU_OK) die(argv[1]);
    situ_board *b = fresh(program, NULL);
    read_stream(b, argv[2]);

    /* Throughput: only the posts are timed. */
    uint64_t changes = 0, timed = 0, start = now_ns();
    for (size_t i = 0; i < n_events; i++) {
        if (post(b, i, &changes)) {
            timed += now_ns() - start;
            b = fresh(program, b);
            start = now_ns();
        }
    }
    timed += now_ns() - start;

    /* Latency: each post alone. */
    uint64_t *lat = malloc(n_events * sizeof *lat), latency_changes = 0;
    b = fresh(program, b);
    for (size_t i = 0; i < n_events; i++) {
        uint64_t t0 = now_ns();
        int final = post(b, i, &latency_changes);
        lat[i] = now_ns() - t0;
        if (final) b = fresh(program, b);
    }
    qsort(lat, n_events, sizeof *lat, cmp_u64);
    uint64_t clock[1001];
    for (int i = 0; i < 1001; i++) {
        uint64_t t0 = now_ns();
        clock[i] = now_ns() - t0;
    }
    qsort(clock, 1001, sizeof *clock, cmp_u64);

    printf("{\"path\": \"C situ_board_post_values\", \"events\": %zu, \"state_changes\": %llu, "
           "\"events_per_sec\": %.0f, \"latency_ns\": {\"p50\": %llu, \"p99\": %llu}, \"timer_overhead_ns\": %llu}\n",
           n_events, (unsigned long long)changes, n_events / (timed / 1e9),
           (unsigned long long)lat[n_events / 2], (unsigned long long)lat[n_events * 99 / 100],
           (unsigned long long)clock[500]);
    situ_board_free(b);
    situ_program_free(program);
    for (size_t i = 0; i < n_names; i++) free(names[i]);
    free(names), free(values), free(events), free(lat);
    return latency_changes == changes ? 0 : 1;
}
