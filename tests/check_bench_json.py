#!/usr/bin/env python3
"""Google Benchmark JSON from bench_kernels, read by a strict parser.

usage: check_bench_json.py FILE.json

Fails on a duplicate key in any object (Python's json module would keep the
last one silently), on non-finite numbers, and where a benchmark lacks the
counters the README and perf/RESULTS.md quote (DoF/s, bytes/s, omp_threads).
"""
import json
import math
import sys


def strict_object(pairs):
    keys = [k for k, _ in pairs]
    dup = sorted({k for k in keys if keys.count(k) > 1})
    if dup:
        raise ValueError("duplicate keys in one object: %s" % ", ".join(dup))
    return dict(pairs)


def no_constant(name):
    raise ValueError("non-finite number %s in the JSON" % name)


def main():
    with open(sys.argv[1]) as f:
        doc = json.load(f, object_pairs_hook=strict_object, parse_constant=no_constant)
    runs = doc["benchmarks"]
    if not runs:
        raise ValueError("no benchmarks in the file")
    for b in runs:
        for key in ("DoF/s", "bytes/s", "omp_threads", "real_time"):
            if key not in b:
                raise ValueError("%s has no %s" % (b.get("name"), key))
            # (the aggregates of repetitions: a stddev may be 0)
            if b.get("run_type") == "iteration" and not (isinstance(b[key], (int, float)) and math.isfinite(b[key]) and b[key] > 0):
                raise ValueError("%s: %s = %r" % (b["name"], key, b[key]))
    if "tresca kernels" not in doc["context"]:
        raise ValueError("the context has no build line ('tresca kernels')")
    print("bench JSON ok: %d runs, strict parse, counters present" % len(runs))


if __name__ == "__main__":
    try:
        main()
    except (ValueError, KeyError) as e:
        print("check_bench_json: %s" % e, file=sys.stderr)
        sys.exit(1)
