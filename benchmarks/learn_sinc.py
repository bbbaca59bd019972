"""Learn Takagi-Sugeno systems for known functions and compare with published figures.

    python benchmarks/learn_sinc.py [--budget 150]

1. sin(x)/x on [-10, 10]: 101 training points (step 0.2), checking at the 100 midpoints;
   grid partition with 5, 7, 9 terms, least-squares consequents (``fuzzyctl learn``), then
   the premises tuned by least squares with the closed-form gradient (``fuzzyctl tune``).
2. MATLAB's documented tunefis example: x = 0:0.1:10, y = sin(2x) / exp(x/5), grid
   partition with 5 membership functions; the documentation prints the ANFIS training RMSE
   per epoch (0.0694086, 0.0680259, 0.066663 for epochs 1-3).
3. The two-input sinc of Jang's ANFIS paper: sin(x)/x * sin(y)/y on an 11 x 11 grid of
   [-10, 10]^2 (121 points), 5 terms per input (25 rules, 75 consequents); the R package
   anfis documents a last training error of 0.01916307 for that set-up (5 Gaussian MFs per
   input, 10 epochs of Jang's hybrid training).  Checking on the 20 x 20 cell centres.

Prints one table; the numbers are quoted in docs/tune.md."""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np


def sinc(x: np.ndarray) -> np.ndarray:
    return np.sinc(x / np.pi)  # numpy's sinc is sin(pi x) / (pi x)


def rmse(doc: object, cols: dict[str, np.ndarray], out: str) -> float:
    import fuzzyctl

    ctl = fuzzyctl.compile(doc)  # type: ignore[arg-type]
    pred = ctl.evaluate_batch({k: v for k, v in cols.items() if k != out})[out]
    return float(np.sqrt(np.mean((pred - cols[out]) ** 2)))


def case(
    name: str,
    train: dict[str, np.ndarray],
    check: dict[str, np.ndarray] | None,
    inputs: list[str],
    terms: int,
    budget: int,
    shape: str = "triangle",
) -> list[str]:
    import fuzzyctl

    t0 = time.perf_counter()
    learned = fuzzyctl.learn(train, inputs=inputs, output="y", terms=terms, validation=0.0, shape=shape)
    t1 = time.perf_counter()
    tuned = fuzzyctl.tune(learned.document, data=train, output="y", validation=0.0, budget=budget, workers=0)
    t2 = time.perf_counter()
    rows = []
    for label, doc, secs in (
        ("learn", learned.document, t1 - t0),
        (f"learn + tune (lsq, {tuned.evaluations} ev.)", tuned.document, t2 - t1),
    ):
        tr = rmse(doc, train, "y")
        ch = rmse(doc, check, "y") if check is not None else float("nan")
        rows.append(f"| {name} | {terms} {shape} | {label} | {tr:.5f} | {ch:.5f} | {secs:.1f} |")
    return rows


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--budget", type=int, default=150)
    args = ap.parse_args()

    x = np.round(np.arange(-10.0, 10.0001, 0.2), 10)
    xc = x[:-1] + 0.1
    rows = []
    for terms, shape in ((5, "triangle"), (5, "gauss"), (9, "triangle"), (9, "gauss")):
        rows += case(
            "sin(x)/x", {"x": x, "y": sinc(x)}, {"x": xc, "y": sinc(xc)}, ["x"], terms, args.budget, shape
        )
    xm = np.round(np.arange(0.0, 10.0001, 0.1), 10)
    xmc = xm[:-1] + 0.05
    f = lambda v: np.sin(2 * v) / np.exp(v / 5)  # noqa: E731
    for shape in ("triangle", "gauss"):
        rows += case(
            "sin(2x)/exp(x/5) (MATLAB tunefis)",
            {"x": xm, "y": f(xm)},
            {"x": xmc, "y": f(xmc)},
            ["x"],
            5,
            args.budget,
            shape,
        )
    g = np.linspace(-10, 10, 11)
    gx, gy = np.meshgrid(g, g)
    c = np.linspace(-9.5, 9.5, 20)
    cx, cy = np.meshgrid(c, c)
    two = {"x": gx.ravel(), "z": gy.ravel(), "y": (sinc(gx) * sinc(gy)).ravel()}
    two_check = {"x": cx.ravel(), "z": cy.ravel(), "y": (sinc(cx) * sinc(cy)).ravel()}
    for shape in ("triangle", "gauss"):
        rows += case("sinc(x) sinc(y), 121 points (Jang)", two, two_check, ["x", "z"], 5, args.budget, shape)
    print("| function | terms per input | system | training RMSE | checking RMSE | seconds |")
    print("|---|---|---|---|---|---|")
    print("\n".join(rows))
    print(
        "\nreference: MATLAB tunefis doc, same data and 5 MFs: ANFIS training RMSE "
        "0.0694086 (epoch 1), 0.0680259 (2), 0.066663 (3)"
    )
    print(
        "reference: R package anfis, two-input sinc, 121 points, 5 MFs per input, 10 epochs: "
        "last training error 0.01916307"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
