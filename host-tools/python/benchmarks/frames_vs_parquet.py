"""Opening a long log into Polars through the package against reading the
same frames from Parquet, in one process; prints times, ratios and peak
memory. Usage (from the repository root, the package and polars installed):

    python host-tools/python/benchmarks/frames_vs_parquet.py [--minutes 60] [--logs 20] [--scan-minutes 10] [--no-gps]

The CLI (`WOBBLOG_CLI`, else the release build in the target directory)
encodes a synthetic ride of that length and decodes it to Parquet first.
"""

import argparse
import math
import os
import subprocess
import sys
import tempfile
import time
from datetime import datetime, timedelta, timezone
from pathlib import Path

import polars as pl

import wobblog

ROOT = Path(__file__).resolve().parents[3]


def cli():
    if os.environ.get("WOBBLOG_CLI"):
        return os.environ["WOBBLOG_CLI"]
    target = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    return str(target / "release" / "wobblog")


def encode(directory, minutes, run=1, gps=True):
    """A ride of `minutes` at 100 Hz with every IMU channel moving (a
    different weave per `run`, so no two logs are copies) and, with `gps`,
    a 3D fix moving north every 50 ms (20 Hz, as the receiver sends them)
    and UTC in every row, as outdoors."""
    csv = directory / f"ride{run}.csv"
    weave_hz = 0.6 + 0.01 * run
    start = datetime(2026, 6, 1, 10, 0, tzinfo=timezone.utc)
    with csv.open("w") as f:
        gps_header = ",gps_lat_deg,gps_lon_deg,gps_speed_mps,gps_fix,utc" if gps else ""
        f.write(f"t_s,ax_g,ay_g,az_g,gx_dps,gy_dps,gz_dps,steer_deg,speed_mps{gps_header}\n")
        for i in range(minutes * 60 * 100):
            t = i / 100
            s = math.sin(2 * math.pi * 6.4 * t)
            w = math.sin(2 * math.pi * weave_hz * t)
            f.write(f"{t:.2f},{0.01 * s:.4f},{0.1 * w:.4f},1.0,{5 * w:.3f},"
                    f"{2 * s:.3f},{3 * w:.3f},{s + 2 * w:.2f},{4 + 0.5 * w:.3f}")
            if gps:
                fix_s = i // 5 * 0.05
                utc = (start + timedelta(milliseconds=10 * i)).isoformat(timespec="milliseconds")
                speed = 4 + 0.5 * math.sin(2 * math.pi * weave_hz * fix_s)
                f.write(f",{52 + 4e-5 * fix_s:.7f},{4.5:.7f},{speed:.2f},3d,"
                        f"{utc.replace('+00:00', 'Z')}")
            f.write("\n")
    log = directory / f"RUN{run:05d}.WBL"
    subprocess.run([cli(), "encode", "--csv", csv, "-o", log], check=True)
    csv.unlink()
    return log


def timed(work):
    """Wall-clock and CPU time of this process (every thread) of one run of
    `work`, s: on a loaded machine the CPU time shows the work done, the
    wall time also the waits."""
    start, start_cpu = time.perf_counter(), time.process_time()
    result = work()
    elapsed = time.perf_counter() - start, time.process_time() - start_cpu
    del result
    return elapsed


def alternated(n, works):
    """`n` runs of each of `works`, taken in turn (so that neither gains
    from the other's warm caches or a quiet spell of the machine): for each,
    the shortest and the median wall time and the shortest CPU time, s."""
    runs = [[] for _ in works]
    for _ in range(n):
        for times, work in zip(runs, works):
            times.append(timed(work))
    figures = []
    for times in runs:
        wall = sorted(t for t, _ in times)
        figures.append((wall[0], wall[len(wall) // 2], min(c for _, c in times)))
    return figures


def peak_rss_mib(code):
    """Peak resident memory of a fresh interpreter running `code`, MiB: its
    VmHWM (Linux), as getrusage's maxrss carries over this large process's
    peak into a child across exec."""
    read_peak = ("\nprint([l.split()[1] for l in open('/proc/self/status') "
                 "if l.startswith('VmHWM')][0])")
    out = subprocess.run([sys.executable, "-c", code + read_peak],
                         check=True, capture_output=True, text=True)
    return int(out.stdout.split()[-1]) / 1024


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--minutes", type=int, default=60)
    parser.add_argument("--logs", type=int, default=20)
    parser.add_argument("--scan-minutes", type=int, default=10)
    parser.add_argument("--no-gps", action="store_true",
                        help="rides without GPS or UTC (indoors, on rollers)")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        directory = Path(tmp)
        log = encode(directory, args.minutes, gps=not args.no_gps)
        parquet = directory / "ride.parquet"
        subprocess.run([cli(), "decode", log, "-o", parquet], check=True)
        df = wobblog.open(log).frames().to_polars()
        assert df.equals(pl.read_parquet(parquet))
        size_mib = df.estimated_size() / 2**20
        ours, opening, theirs = alternated(15, [
            lambda: wobblog.open(log).frames().to_polars(),
            lambda: wobblog.open(log),
            lambda: pl.read_parquet(parquet),
        ])
        what = "IMU only" if args.no_gps else "IMU, 20 Hz GPS and UTC"
        print(f"{df.height} frames ({args.minutes} min, {what}), DataFrame {size_mib:.1f} MiB; "
              "best and median of 15 runs taken in turn")
        print(f"wobblog.open(p).frames().to_polars(): {ours[0] * 1e3:.1f} ms, median "
              f"{ours[1] * 1e3:.1f} ms, CPU {ours[2] * 1e3:.0f} ms (of which open, the decoding: "
              f"{opening[0] * 1e3:.1f} ms)")
        print(f"polars.read_parquet:                  {theirs[0] * 1e3:.1f} ms, median "
              f"{theirs[1] * 1e3:.1f} ms, CPU {theirs[2] * 1e3:.0f} ms")
        print(f"ratio: {ours[0] / theirs[0]:.2f}, of the medians {ours[1] / theirs[1]:.2f} "
              f"(CPU time: {ours[2] / theirs[2]:.2f})")
        base = peak_rss_mib("import polars, wobblog")
        peak = peak_rss_mib(f"import polars, wobblog; "
                            f"df = wobblog.open({str(log)!r}).frames().to_polars()")
        print(f"peak memory above the imports: {peak - base:.1f} MiB, "
              f"{(peak - base) / size_mib:.2f}x the DataFrame")
        # Scans of a few and of many logs of `--scan-minutes` each: streamed,
        # their peaks should not grow with the number of logs.
        peaks = []
        for n in (2, args.logs):
            card = directory / f"card{n}"
            card.mkdir()
            for run in range(n):
                encode(card, args.scan_minutes, run, gps=not args.no_gps)
            code = (f"import pyarrow as pa, wobblog; r = pa.RecordBatchReader.from_stream("
                    f"wobblog.scan({str(card)!r})); n = sum(b.num_rows for b in r)")
            peaks.append(peak_rss_mib(code) - base)
        print(f"scan of 2 and of {args.logs} logs of {args.scan_minutes} min, streamed: "
              f"peak {peaks[0]:.1f} and {peaks[1]:.1f} MiB above the imports")

if __name__ == "__main__":
    main()
