#!/usr/bin/env python3
"""Generates the rule base of issue 28, on which the static checks were
exponential: S states, A agents of E events each, and N rules

    rule rK salience K { when state in {Si} and AaEe and AbEf then Sj }

with K = 0 ... N-1 and i, a, e, b, f, j drawn uniformly at random. The
draws come from splitmix64 seeded with SEED, so a seed gives the same file
on every machine and Python version.

    python3 bench/gen-random-rules.py N [--seed SEED] [--states 40]
        [--agents 50] [--events 6] > FILE
"""

import argparse
import sys

MASK = (1 << 64) - 1


class SplitMix64:
    def __init__(self, seed):
        self.state = seed & MASK

    def next(self):
        self.state = (self.state + 0x9E3779B97F4A7C15) & MASK
        z = self.state
        z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & MASK
        z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & MASK
        return z ^ (z >> 31)

    def below(self, n):
        """A draw in 0..n (the modulo bias is negligible for small n)."""
        return self.next() % n


def generate(n, seed, states, agents, events, out):
    rng = SplitMix64(seed)
    out.write("states {\n    S0 initial\n")
    for i in range(1, states):
        out.write(f"    S{i}\n")
    out.write("}\n")
    for a in range(agents):
        decls = " ".join(f"event A{a}E{e}" for e in range(events))
        out.write(f"agent A{a} sensor {{ {decls} }}\n")
    for k in range(n):
        i = rng.below(states)
        a, e = rng.below(agents), rng.below(events)
        b, f = rng.below(agents), rng.below(events)
        j = rng.below(states)
        out.write(f"rule r{k} salience {k} {{ when state in {{S{i}}} and A{a}E{e} and A{b}E{f} then S{j} }}\n")


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("rules", type=int)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--states", type=int, default=40)
    p.add_argument("--agents", type=int, default=50)
    p.add_argument("--events", type=int, default=6)
    args = p.parse_args()
    if min(args.states, args.agents, args.events) < 1 or args.rules < 0:
        p.error("states, agents and events must be at least 1, rules at least 0")
    generate(args.rules, args.seed, args.states, args.agents, args.events, sys.stdout)


if __name__ == "__main__":
    main()
