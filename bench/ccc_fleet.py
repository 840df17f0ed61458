#!/usr/bin/env python3
"""Writes a fleet CSV of N cars in random order: connected cruise control cars (ccc, k1 0.1,
k2 0.3, k3 0.2, th 1.2 s, tau 0.4 s, tau2 0.1 s) with probability SHARE, the calibrated A_min
otherwise; the order from random.seed(SEED). The spectrum of such a ring depends on the order.
    python3 bench/ccc_fleet.py N SEED [SHARE] > ccc.csv"""
import random
import sys

n = int(sys.argv[1]) if len(sys.argv) > 1 else 2000
random.seed(int(sys.argv[2]) if len(sys.argv) > 2 else 1)
share = float(sys.argv[3]) if len(sys.argv) > 3 else 0.5
print("vehicle,model,k1,k2,k3,th,tau,tau2")
for _ in range(n):
    print(",ccc,0.1,0.3,0.2,1.2,0.4,0.1" if random.random() < share else "A_min,,,,,,,")
