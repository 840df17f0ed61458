#!/usr/bin/env python3
"""Writes large sparse linear DDEs as `roots --system` files (triplets), standard library only.

  rd    a delayed reaction-diffusion equation on an nx x ny grid (Dirichlet, lattice units h = 1):
            u_t = dx u_xx + dy u_yy + a u - sum_k b_k u(t - tau_k)
        A0 = dx Lx (+) dy Ly + a I, A_k = -b_k I. Each eigenvalue mu of the discrete Laplacian
        mu_jl = -4 dx sin^2(j pi / (2 (nx + 1))) - 4 dy sin^2(l pi / (2 (ny + 1)))
        gives the scalar characteristic equation lambda = mu + a - sum_k b_k e^{-lambda tau_k}
        (one delay: lambda = c + W_branch(-b tau e^{-c tau}) / tau, c = mu + a).
  ring  a ring of N identical OVRV cars written out (state s_1, v_1, ..., s_N, v_N):
            s_i' = v_{i-1} - v_i,
            v_i' = k1 s_i(t - tau) - (k1 th + k2) v_i + k2 v_{i-1}(t - tau)
        (car 1 follows car N); `ddemap roots --ring N` with the same k1, k2, th, tau is the reference.
  net   a random delayed network of n nodes (fixed seed): x' = -d x + W0 x + W1 x(t - tau), W0 and W1
        with `--degree` entries per row at random columns, normal weights of standard deviation
        s0 / sqrt(degree) and s1 / sqrt(degree) (no clustered spectrum: the rightmost roots are
        separated, unlike rd and ring).

Examples:
  python3 bench/sparse_systems.py rd --nx 100 --ny 100 --out out/rd10000.json
  python3 bench/sparse_systems.py rd --nx 40 --ny 25 --b 1,0.3 --tau 2,0.7 --out out/rd1000_2.json
  python3 bench/sparse_systems.py ring --cars 5000 --out out/ring10000.json
"""
import argparse
import json
import random
import sys


def floats(text):
    return [float(x) for x in text.split(",")]


def rd(args):
    nx, ny = args.nx, args.ny
    b, tau = floats(args.b), floats(args.tau)
    if len(b) != len(tau):
        sys.exit("sparse_systems.py: error: --b and --tau need the same number of values")
    idx = lambda i, j: i + nx * j
    a0 = []
    for j in range(ny):
        for i in range(nx):
            p = idx(i, j)
            a0.append([p, p, -2.0 * args.dx - 2.0 * args.dy + args.a])
            if i > 0:
                a0.append([p, idx(i - 1, j), args.dx])
            if i < nx - 1:
                a0.append([p, idx(i + 1, j), args.dx])
            if j > 0:
                a0.append([p, idx(i, j - 1), args.dy])
            if j < ny - 1:
                a0.append([p, idx(i, j + 1), args.dy])
    n = nx * ny
    mats = [{"triplets": [[p, p, -bk] for p in range(n)]} for bk in b]
    comment = ("delayed reaction-diffusion on a %d x %d grid: u' = %g u_xx + %g u_yy + %g u - sum_k b_k u(t - tau_k), b = %s, tau = %s"
               % (nx, ny, args.dx, args.dy, args.a, args.b, args.tau))
    return {"comment": comment, "dimension": n, "delays": tau, "A0": {"triplets": a0}, "A": mats}


def ring(args):
    cars = args.cars
    a0, a1 = [], []
    for i in range(cars):
        ahead = (i + cars - 1) % cars
        s, v, va = 2 * i, 2 * i + 1, 2 * ahead + 1
        a0 += [[s, va, 1.0], [s, v, -1.0], [v, v, -(args.k1 * args.th + args.k2)]]
        a1 += [[v, s, args.k1], [v, va, args.k2]]
    comment = ("ring of %d OVRV cars: k1 = %g, k2 = %g, th = %g, tau = %g" % (cars, args.k1, args.k2, args.th, args.tau))
    return {"comment": comment, "dimension": 2 * cars, "delays": [args.tau], "A0": {"triplets": a0}, "A": [{"triplets": a1}]}


def net(args):
    rng = random.Random(args.seed)
    n, deg = args.n, args.degree
    def random_rows(sd):
        t = []
        for i in range(n):
            for j in rng.sample(range(n), deg):
                t.append([i, j, rng.gauss(0.0, sd / deg ** 0.5)])
        return t
    a0 = [[i, i, -args.d] for i in range(n)] + random_rows(args.s0)
    a1 = random_rows(args.s1)
    comment = ("random delayed network of %d nodes, %d entries per row: x' = -%g x + W0 x + W1 x(t - %g), sd %g / sqrt(%d) and %g / sqrt(%d), seed %d"
               % (n, deg, args.d, args.tau, args.s0, deg, args.s1, deg, args.seed))
    return {"comment": comment, "dimension": n, "delays": [args.tau], "A0": {"triplets": a0}, "A": [{"triplets": a1}]}


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="kind", required=True)
    r = sub.add_parser("rd")
    r.add_argument("--nx", type=int, default=100)
    r.add_argument("--ny", type=int, default=100)
    r.add_argument("--dx", type=float, default=1.0)
    r.add_argument("--dy", type=float, default=0.37)
    r.add_argument("--a", type=float, default=0.5)
    r.add_argument("--b", default="1")
    r.add_argument("--tau", default="2")
    g = sub.add_parser("ring")
    g.add_argument("--cars", type=int, default=500)
    g.add_argument("--k1", type=float, default=0.2)
    g.add_argument("--k2", type=float, default=0.4)
    g.add_argument("--th", type=float, default=1.5)
    g.add_argument("--tau", type=float, default=0.5)
    w = sub.add_parser("net")
    w.add_argument("--n", type=int, default=10000)
    w.add_argument("--degree", type=int, default=4)
    w.add_argument("--d", type=float, default=1.0)
    w.add_argument("--s0", type=float, default=0.5)
    w.add_argument("--s1", type=float, default=0.8)
    w.add_argument("--tau", type=float, default=1.0)
    w.add_argument("--seed", type=int, default=1)
    for s in (r, g, w):
        s.add_argument("--out", required=True)
    args = p.parse_args()
    system = {"rd": rd, "ring": ring, "net": net}[args.kind](args)
    with open(args.out, "w") as f:
        json.dump(system, f, separators=(",", ":"))
        f.write("\n")


if __name__ == "__main__":
    main()
