"""The event queue of the MD engines: a 4-ary min-heap with its keys stored in heap order.

``heap[k]`` is the item in slot k and ``hkey[k]`` its key (the predicted event time), so a sift
compares keys that sit next to each other in memory; ``hpos[i]`` is the slot of item i (-1 when
absent). One item per particle, whose key changes in place (Donev's "one event per particle"
schedule, Donev 2006, dissertation sec. 3.4.1). Used by :mod:`hardpack.md._kernel`
and :mod:`hardpack.freeenergy._kernel`; inlined into their event loops.
"""

from __future__ import annotations

from numba import njit


@njit(cache=True, inline="always")
def heap_set(hkey, heap, hpos, hsize, i, key):
    """Give item i the key ``key`` in a 4-ary min-heap whose keys are stored in heap order.

    An absent item is appended first. Sifts up, then down; the arrays are updated in place.

    Parameters
    ----------
    hkey : numpy.ndarray
        Keys in heap order: ``hkey[k]`` is the key of ``heap[k]``.
    heap : numpy.ndarray
        Integer items in heap order.
    hpos : numpy.ndarray
        Slot of each item in ``heap``, -1 if absent.
    hsize : int
        Number of items in the heap.
    i : int
        The item.
    key : float
        Its new key.

    Returns
    -------
    int
        The new heap size (``hsize + 1`` when i was absent, else ``hsize``).
    """
    pos = hpos[i]
    if pos < 0:
        pos = hsize
        hsize += 1
    while pos > 0:  # sift up
        parent = (pos - 1) >> 2
        if hkey[parent] <= key:
            break
        hp = heap[parent]
        hkey[pos] = hkey[parent]
        heap[pos] = hp
        hpos[hp] = pos
        pos = parent
    while True:  # sift down: smallest of up to 4 children
        first = 4 * pos + 1
        if first >= hsize:
            break
        ch = first
        kc = hkey[first]
        for c in range(first + 1, min(first + 4, hsize)):
            if hkey[c] < kc:
                kc = hkey[c]
                ch = c
        if kc >= key:
            break
        hc = heap[ch]
        hkey[pos] = kc
        heap[pos] = hc
        hpos[hc] = pos
        pos = ch
    hkey[pos] = key
    heap[pos] = i
    hpos[i] = pos
    return hsize
