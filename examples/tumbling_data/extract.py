"""Build the phone-toss CSVs from the verbatim source excerpt.

The excerpt ``source_excerpt_RawData_3.tsv`` holds rows copied verbatim from
``experiment/Raw Data_3.csv`` of github.com/weenming/TRE (commit
5d87b937d75ce06598dbbd60164c05e2a44ffa22): a phyphox "Gyroscope rotation rate"
export, tab separated, time in s, rates in rad/s about the phone's own axes.
It covers two tosses, each with a few in-hand samples before the release and
after the catch.  This script keeps only the samples of the free flight (the
windows below, chosen by eye from the data; see SOURCE.md), renames the
columns, and shifts time to start at 0 for each toss.  No value is altered:
each rate is the source's decimal number, written in plain notation; the
source time is kept as ``t_phyphox``.

Run:  python extract.py    (writes phone_toss_1.csv, phone_toss_2.csv)
"""

from decimal import Decimal
from pathlib import Path

HERE = Path(__file__).resolve().parent
SOURCE = HERE / "source_excerpt_RawData_3.tsv"

# Free-flight windows, inclusive, in the source's own time (s).
WINDOWS = {
    "phone_toss_1.csv": (Decimal("128.5988510"), Decimal("129.1961660")),
    "phone_toss_2.csv": (Decimal("142.4366758"), Decimal("143.0240368")),
}


def plain(s: str) -> str:
    """'1.938242531E1' -> '19.38242531' (same decimal value, no rounding)."""
    d = Decimal(s)
    out = format(d, "f")
    if "." in out:
        out = out.rstrip("0").rstrip(".")
    return out if out not in ("", "-0") else "0"


def main() -> None:
    lines = SOURCE.read_text().splitlines()
    rows = [ln.split("\t") for ln in lines[1:] if ln.strip()]
    for name, (t0, t1) in WINDOWS.items():
        sel = [r for r in rows if t0 <= Decimal(r[0]) <= t1]
        start = Decimal(sel[0][0])
        with open(HERE / name, "w") as f:
            f.write("t,wx,wy,wz,t_phyphox\n")
            for t, wx, wy, wz, _absw in sel:
                dt = Decimal(t) - start
                f.write(",".join([plain(str(dt)), plain(wx), plain(wy), plain(wz), plain(t)]) + "\n")
        print(f"{name}: {len(sel)} samples, {float(Decimal(sel[-1][0]) - start):.4f} s")


if __name__ == "__main__":
    main()
