"""The cost of the Python front door: the same scene run by `polydem run` and by `Simulation.run` from
Python, both writing the same outputs (the CSV series), timed in the same process tree, alternating.

    python python/examples/speed_vs_cli.py [SCENE] [--end-time T] [--rounds N] [--polydem PATH]

Prints, per round, the wall and CPU time of each and their ratio, with the load average; a ratio near 1
says the Python package adds nothing measurable to a run. Both sides must produce the same bodies.csv
(checked).
"""

import argparse
import os
import pathlib
import resource
import subprocess
import tempfile
import time

import polydem

REPO = pathlib.Path(__file__).resolve().parents[2]


def children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def run_cli(binary, scene, end_time, out):
    cpu0, t0 = children_cpu(), time.perf_counter()
    subprocess.run([binary, "run", scene, "--out", out, "--quiet", "--end-time", repr(end_time)],
                   check=True, stdout=subprocess.DEVNULL, stdin=subprocess.DEVNULL)
    return time.perf_counter() - t0, children_cpu() - cpu0


def run_python(scene, end_time, out):
    sim = polydem.Simulation.from_toml(scene)
    cpu0, t0 = time.process_time(), time.perf_counter()
    sim.run(until=end_time, out=out)
    return time.perf_counter() - t0, time.process_time() - cpu0


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene", nargs="?", default=str(REPO / "scenes/sphere_bed_a_hertz_5ms.toml"))
    parser.add_argument("--end-time", type=float, default=0.01)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--polydem", default=str(REPO / "target/release/polydem"))
    args = parser.parse_args()
    print(f"scene {args.scene}, end time {args.end_time} s, {args.rounds} rounds")
    print("round  cli wall [s]  cli cpu [s]  python wall [s]  python cpu [s]  python/cli wall  load average")
    with tempfile.TemporaryDirectory() as tmp:
        for k in range(args.rounds):
            cli_out, py_out = f"{tmp}/cli{k}", f"{tmp}/py{k}"
            cli = run_cli(args.polydem, args.scene, args.end_time, cli_out)
            py = run_python(args.scene, args.end_time, py_out)
            same = (pathlib.Path(cli_out, "bodies.csv").read_bytes() == pathlib.Path(py_out, "bodies.csv").read_bytes())
            if not same:
                raise SystemExit(f"round {k + 1}: bodies.csv differs between the command and Python")
            load = " ".join(f"{x:.2f}" for x in os.getloadavg())
            print(f"{k + 1:5d}  {cli[0]:12.3f}  {cli[1]:11.3f}  {py[0]:15.3f}  {py[1]:14.3f}  {py[0] / cli[0]:15.3f}  {load}")


if __name__ == "__main__":
    main()
