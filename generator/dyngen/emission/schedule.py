"""Statement order for the register allocator: fewer values live at once, fewer spills.

gcc -O2 on x86-64 keeps the order of a basic block's statements (no pre-allocation
scheduling) and has 16 floating-point registers; a value computed long before its last use
is stored to the stack and loaded again. A straight-line program's statements may come in
any order that respects their dependencies, so this greedy list scheduler picks, among the
statements whose operands exist, the one that ends the most live values and starts the
fewest (a sine/cosine pair counts as two values, started by its first reader), then the
earliest in the original order (so ties keep the per-link reading order). Preferring the
statement that reads the latest value (depth first) was tried: more values live, more
instructions (Panda rnea 1731 Ir per call against 1721 unscheduled and 1675 with this rule). Same statements, same operations, same
results to the bit: only the order of independent statements changes.
"""

from __future__ import annotations

LARGEST = 4000  # statements; above it the quadratic search costs more generation time than it saves
# Functions whose statements are not sunk (_sunk): measured per call at -O2, gcc 12, in a probe
# loop of the function alone (issue 24, h40), sinking costs rnea instructions on every example
# arm (PUMA 560 1740 -> 1769, UR5 1743 -> 1757, Stanford 1529 -> 1541, LWR 1921 -> 1929, Panda
# 1995 -> 1996) while it saves them on forward dynamics (PUMA 2794 -> 2779, Panda 3356 -> 3314,
# LWR 3110 -> 3096), M and gravity on nearly every arm. An estimate of the stack traffic (Belady's
# allocation with 16 registers) ranks rnea's two orders the other way round, so the choice rests
# on the measurement, per function.
NOT_SUNK = frozenset({"rnea"})


def scheduled(assignments: list, outputs_free: set, trig: dict, sink: bool = True) -> list:
    """assignments reordered (a topological order of their dependencies). outputs_free: the
    symbols the outputs read (they stay live to the end); trig: symbol -> (joint, fn); sink:
    then move statements down to their first reader (_sunk)."""
    n = len(assignments)
    if n > LARGEST or n < 3:
        return assignments
    index = {a.symbol: k for k, a in enumerate(assignments)}
    reads = [sorted(index[s] for s in a.expr.free_symbols if s in index) for a in assignments]
    angles = [sorted({trig[s][0] for s in a.expr.free_symbols if s in trig}) for a in assignments]
    users = [0] * n
    for deps in reads:
        for d in deps:
            users[d] += 1
    for s in outputs_free:
        if s in index:
            users[index[s]] += 1  # kept to the end
    angle_users: dict = {}
    for joints in angles:
        for j in joints:
            angle_users[j] = angle_users.get(j, 0) + 1
    waiting = [len(deps) for deps in reads]
    readers = [[] for _ in range(n)]
    for k, deps in enumerate(reads):
        for d in deps:
            readers[d].append(k)

    def score(k):
        ended = sum(1 for d in reads[k] if users[d] == 1)
        ended += sum(2 for j in angles[k] if angle_users[j] == 1)
        started = (1 if users[k] else 0) + sum(2 for j in angles[k] if opened.get(j) is None)
        return (ended - started, -k)

    ready = {k for k in range(n) if not reads[k]}
    order = []
    opened: dict = {}
    while ready:
        k = max(ready, key=score)
        ready.discard(k)
        order.append(assignments[k])
        for d in reads[k]:
            users[d] -= 1
        for j in angles[k]:
            opened[j] = True
            angle_users[j] -= 1
        for r in readers[k]:
            waiting[r] -= 1
            if waiting[r] == 0:
                ready.add(r)
    return _sunk(order, outputs_free, set(trig)) if sink else order


def _sunk(order: list, outputs_free: set, trig: set) -> list:
    """order with each statement moved down to just before its first reader when every value
    it reads stays alive there anyway (an input, or a value read again at or after that point):
    its result is then live for a shorter stretch and no other value for a longer one. The
    greedy order places a statement that reads only inputs (a product of two parameters, a
    sum of a joint's rate and acceleration) as early as it can, where it holds a register over
    statements that do not need it. Processed from the end, so a chain of such statements
    sinks together; dependencies are kept (a statement only moves to before its first reader)."""
    values = {a.symbol for a in order} | trig
    readers: dict = {}
    for k, a in enumerate(order):
        for s in a.expr.free_symbols & values:
            readers.setdefault(s, []).append(k)
    # a position is a tuple: statement k starts at (k, 0); one sunk to before the statement at
    # (..., 0) gets (..., -m, 0), m counting the moves, so later moves to the same place come first
    key = [(k, 0) for k in range(len(order))]
    for m, k in enumerate(reversed(range(len(order)))):
        a = order[k]
        if a.symbol in outputs_free or a.symbol not in readers:
            continue
        first = min((key[r] for r in readers[a.symbol]), default=None)
        alive = all(s in outputs_free or any(r != k and key[r] >= first for r in readers[s])
                    for s in a.expr.free_symbols & values)
        if alive:
            key[k] = first[:-1] + (-(m + 1), 0)
    return [order[k] for k in sorted(range(len(order)), key=key.__getitem__)]
