#!/usr/bin/env python3
"""How often a 5-run bench passes issue 5's outlier rule, from the runs of several benches.

Pools each sequence's runs per configuration (`hiveslam bench --out DIR` folders), draws five
of them at random (with replacement, 20,000 times) and prints the share of draws that pass
max <= 1.5 x median, and max <= max(1.5 x median, median + 5 mm).

  scripts/outlier_odds.py --one B47 B48 B49 B50 --three B49 B50
"""
import argparse
import glob
import json
import random
import statistics as st


def runs(benches, seq, nodes):
    out = []
    for bench in benches:
        for path in sorted(glob.glob(f"{bench}/{seq}/{nodes}node_run*/tr/report.json")):
            with open(path) as f:
                out.append(1e3 * json.load(f)["ate"]["rmse"])
    return out


def share(ates, rule, draws=20000):
    return sum(rule([random.choice(ates) for _ in range(5)]) for _ in range(draws)) / draws


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--one", nargs="+", required=True, help="bench folders with 1-node runs")
    ap.add_argument("--three", nargs="+", required=True, help="bench folders with 3-node runs")
    ap.add_argument("--sequences", nargs="+", default=["sweep", "blackout", "figure8", "bigloop"])
    args = ap.parse_args()
    random.seed(1)
    strict = lambda s: max(s) <= 1.5 * st.median(s)
    floor = lambda s: max(s) <= max(1.5 * st.median(s), st.median(s) + 5)
    all_four = {1: [1.0, 1.0], 3: [1.0, 1.0]}
    for seq in args.sequences:
        for nodes, benches in ((1, args.one), (3, args.three)):
            ates = runs(benches, seq, nodes)
            if not ates:
                print(f"{seq} {nodes}-node: no runs")
                continue
            p_strict, p_floor = share(ates, strict), share(ates, floor)
            all_four[nodes][0] *= p_strict
            all_four[nodes][1] *= p_floor
            print(f"{seq:9s} {nodes}-node  runs {len(ates):2d}  median {st.median(ates):.2f} mm  max {max(ates):.2f} mm"
                  f"  P(pass 1.5x) {p_strict:.2f}  P(pass with a 5 mm floor) {p_floor:.2f}")
    for nodes in (1, 3):
        print(f"{nodes}-node, every sequence in one bench: P(pass 1.5x) {all_four[nodes][0]:.2f}, "
              f"with a 5 mm floor {all_four[nodes][1]:.2f}")


if __name__ == "__main__":
    main()
