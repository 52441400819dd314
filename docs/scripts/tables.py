"""Prints the tables of docs/findings.md as Markdown from the output folders that
docs/scripts/findings.sh fills (python3 docs/scripts/tables.py TABLE OUT_DIR)."""
import csv
import math
import os
import sys


def rows(path):
    if not os.path.exists(path):
        return []
    with open(path) as f:
        return list(csv.DictReader(line for line in f if not line.startswith("#")))


def thesis(out):
    print("| n | fz/(n Pcrit) at ε = 0.5 | fx/(n Pcrit) | energy (J) | unstable directions at 0.5 | lowest eigenvalue (J/m) | critical points |")
    print("|---|---:|---:|---:|---:|---:|---|")
    for name in ["n1", "n2", "n2-switch", "n4", "n8"]:
        load = rows(f"{out}/{name}/load.csv")
        last = load[-1]
        crit = rows(f"{out}/{name}/critical.csv")
        points = "; ".join(
            f"{c['kind']} at ε = {float(c['eps']):.4f} ({c['unstable_before']} → {c['unstable_after']})"
            for c in crit) or "none"
        label = name[1:].replace("-switch", ', `branch = "switch"`')
        fx = float(last["fx"])
        fx = 0.0 if abs(fx) < 5e-5 else fx
        print(f"| {label} | {float(last['fz']):.4f} | {fx:.4f} | "
              f"{float(last['energy']):.2f} | {last['unstable_dirs']} | "
              f"{float(last['lowest_eig']):.2f} | {points} |")


def sweep_helices(out):
    print("| n | tip | model | unknowns | fz/(n Pcrit) at 0.5 | stable at 0.5 | first critical ε | kind, count | wall (s) |")
    print("|---:|---|---|---:|---:|---|---:|---|---:|")
    for r in rows(f"{out}/sweep-helices/sweep.csv"):
        tip = "fixed" if "fixed" in r["boundary.tip"] else "slide"
        ce = f"{float(r['critical_eps']):.4f}" if r["critical_eps"] else "–"
        kc = f"{r['critical_kind']} {r['critical_change']}" if r["critical_kind"] else "–"
        print(f"| {r['geometry.helices']} | {tip} | {r['model']} | {r['unknowns']} | "
              f"{float(r['fz']):.4f} | {'yes' if r['stable'] == '1' else 'no'} | {ce} | {kc} | "
              f"{float(r['wall_s']):.2f} |")


def sweep_turns(out):
    print("| turns | h0/(2a) | unknowns | fz/(n Pcrit) at 0.5 | energy (J) | stable at 0.5 | first critical ε | count | wall (s) |")
    print("|---:|---:|---:|---:|---:|---|---:|---|---:|")
    for r in rows(f"{out}/sweep-turns/sweep.csv"):
        turns = float(r["geometry.turns"])
        ratio = 2 * math.pi * 0.025 * turns / (2 * 0.06)
        ce = f"{float(r['critical_eps']):.4f}" if r["critical_eps"] else "–"
        print(f"| {turns:g} | {ratio:.2f} | {r['unknowns']} | {float(r['fz']):.4f} | "
              f"{float(r['energy']):.2f} | {'yes' if r['stable'] == '1' else 'no'} | {ce} | "
              f"{r['critical_change'] or '–'} | {float(r['wall_s']):.2f} |")


HYPOTHESES = {"helix": "Kirchhoff, stress-free helical",
              "straight": "Kirchhoff, stress-free straight",
              "sadowsky": "Sadowsky ribbon, flat"}
SUPPORTS = {"clamped": "clamped", "slide": "tip slides", "radial": "base radial + hinge"}


def hypotheses(out):
    print("| hypothesis | supports | path | Fz/(n Pcrit) at ε = 0 | energy at ε = 0 (J) | "
          "Fz/(n Pcrit) at ε = ±0.3 | Fz/(n Pcrit) at ε = ±0.5 | unstable directions at ε = 0 / "
          "last step | first critical point | bulk κ1 spread at ±0.5 |")
    print("|---|---|---|---:|---:|---:|---:|---|---|---:|")
    for h, hname in HYPOTHESES.items():
        for s, sname in SUPPORTS.items():
            for path in ["compression", "extension"]:
                folder = f"{out}/n8-{h}-{s}-{path}"
                load = rows(f"{folder}/load.csv")
                if not load:
                    print(f"| {hname} | {sname} | {path} | no equilibrium at ε = 0 | | | | | | |")
                    continue

                def at(eps):
                    for r in load:
                        if abs(abs(float(r["eps"])) - eps) < 1e-9:
                            return f"{float(r['fz']):.4f}"
                    return None

                crit = rows(f"{folder}/critical.csv")
                stopped = "– (stopped after 16 critical points)" if len(crit) >= 16 else "– (not reached)"
                f3 = at(0.3) or stopped
                f5 = at(0.5) or stopped
                unstable = f"{load[0]['unstable_dirs']} / {load[-1]['unstable_dirs']}"
                if crit:
                    c = crit[0]
                    first = (f"{c['kind']} at ε = {float(c['eps']):.4f} "
                             f"({c['unstable_before']} → {c['unstable_after']})")
                    if len(crit) > 1:
                        first += f", {len(crit) - 1} more"
                else:
                    first = "none"
                spread = "–"
                if at(0.5):
                    k1 = [float(r["k1"]) for r in rows(f"{folder}/state.csv")
                          if r["rod"] == "0" and 0.3 <= float(r["s_over_l"]) <= 0.7]
                    mean = sum(k1) / len(k1)
                    spread = f"{(max(k1) - min(k1)) / abs(mean):.2e}"
                f0, e0 = float(load[0]["fz"]), float(load[0]["energy"])
                f0 = "0" if abs(f0) < 1e-6 else f"{f0:.3f}"
                e0 = "0" if abs(e0) < 1e-6 else f"{e0:.0f}"
                print(f"| {hname} | {sname} | {path} | {f0} | {e0} | {f3} | {f5} | {unstable} | "
                      f"{first} | {spread} |")


def tube(out):
    print("| n | turns | elements/rod | ε = 0.1 | ε = 0.3 | ε = 0.5 | bulk s/L at ε = 0.5 | first critical ε |")
    print("|---:|---:|---:|---:|---:|---:|---|---:|")
    for n in [2, 4, 8, 16]:
        for turns in ["3.5", "7", "14", "28"]:
            folder = f"{out}/tube-n{n}-t{turns}"
            bulk = rows(f"{folder}/bulk.csv")
            if not bulk:
                continue
            elements = int(48 * float(turns) / 3.5)

            def ratio(eps):
                for r in bulk:
                    if r["rod"] == "0" and abs(float(r["eps"]) - eps) < 1e-9 and r["tube_ratio"]:
                        return f"{float(r['tube_ratio']):.4f}"
                return "–"

            extent = "–"
            for r in bulk:
                if r["rod"] == "0" and abs(float(r["eps"]) - 0.5) < 1e-9:
                    extent = f"{float(r['bulk_start']):.2f}–{float(r['bulk_end']):.2f}"
            crit = rows(f"{folder}/critical.csv")
            first = f"{float(crit[0]['eps']):.4f}" if crit else "–"
            print(f"| {n} | {turns} | {elements} | {ratio(0.1)} | {ratio(0.3)} | {ratio(0.5)} | "
                  f"{extent} | {first} |")


TABLES = {"thesis": thesis, "sweep-helices": sweep_helices, "sweep-turns": sweep_turns,
          "hypotheses": hypotheses, "tube": tube}

if __name__ == "__main__":
    if len(sys.argv) != 3 or sys.argv[1] not in TABLES:
        sys.exit(f"usage: python3 docs/scripts/tables.py {'|'.join(TABLES)} OUT_DIR")
    TABLES[sys.argv[1]](sys.argv[2])
