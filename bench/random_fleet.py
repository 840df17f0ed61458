#!/usr/bin/env python3
"""Writes a fleet CSV of N different OVRV cars (the worst case of the product path: one car
type per car). Parameters uniform in k1 [0.02, 0.42], k2 [0.05, 0.65], th [0.6, 2.4] s,
tau [0.1, 1.0] s, from random.seed(SEED).
    python3 bench/random_fleet.py N SEED > rand.csv"""
import random
import sys

n = int(sys.argv[1]) if len(sys.argv) > 1 else 2000
random.seed(int(sys.argv[2]) if len(sys.argv) > 2 else 1)
print("model,k1,k2,th,tau")
for _ in range(n):
    print("ovrv,%.6f,%.6f,%.6f,%.6f" % (0.02 + 0.4 * random.random(), 0.05 + 0.6 * random.random(),
                                       0.6 + 1.8 * random.random(), 0.1 + 0.9 * random.random()))
