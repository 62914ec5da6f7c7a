"""The truth-free verdict: how well each tracker followed a recording, estimated from what a robot
owner has (the scans, the map, the odometry and the trackers' answers), never the truth.

Per scan and tracker, four signals (each its own module): ``mapfit`` (the share of the scan's
returns that land within a few centimetres of the map at the answer), ``consensus`` (whether the
answer agrees with the pose that independent other trackers agree on), ``odometry`` (how far the
answer moved from the odometry's prediction, beyond the recording's measured odometry noise:
jumps), and ``reconverge`` (restarted from a perturbed pose, does the tracker come back to its own
trajectory). ``belief`` combines them into one per-scan judgement, *believed tracked*, and
``score`` turns that into the verdict: the estimated tracked share with its interval.
``agreement`` compares the verdict with the truth where a recording has one. The rules and every
value: ``config`` (chosen on the development split, docs/truth-free.md).
"""
