"""A sweep in a few lines: the tutorial's experiment at three wave frequencies, with and without gravity
feed-forward, each run's largest tracking error per joint in a pandas DataFrame.

    python sweep.py
"""
import itertools

import numpy as np
import pandas as pd

import armscope

rows = []
for freq, no_ff in itertools.product([0.25, 0.5, 1.0], [False, True]):
    r = armscope.run(duration=10, freq=freq, no_ff=no_ff)
    settled = r.t > 2.0  # after the start's transient
    error = np.abs(r.q - r.q_target)[settled].max(axis=0)
    rows.append({"freq rad/s": freq, "feed-forward": not no_ff, **{f"J{j + 1} mrad": 1e3 * e for j, e in enumerate(error)}})
table = pd.DataFrame(rows).set_index(["freq rad/s", "feed-forward"])
print(table.round(1))
