"""The learned method that averages two networks: HeterSkinNet and SkinningNet.

Two networks trained on the same characters with different inputs
(HeterSkinNet reads HollowDist and messages between vertices and bones,
SkinningNet volumetric geodesics and mesh and skeleton graphs) err in
different places; the mean of their raw weights, pruned and sharpened as
one network's are (``predict.finished_weights``), is nearer the artists'
than either. Measured on the held-out training characters of the
419-character split (``scripts/tune_skin_pruning.py``, 2026-11-26), at the
shipped pruning threshold and power: L1 0.4082 against HeterSkinNet's 0.4199
and SkinningNet's 0.4317 (over at most two per skeleton family: 0.4928
against 0.5066 and 0.5213), influence precision 0.818 against 0.821, recall
0.750 against 0.730. Adding RigNet makes it worse (0.4138), and HeterSkinNet
weighted 0.4 or 0.6 changes L1 by under 0.0003, so the two count alike. It
costs the two networks' time (about 1.3 s against 0.8 s on the validation
characters).

On the 91 validation characters (``eval skin --method ensemble``,
2026-11-26) it is nearer the artists on the families with smooth weights
(Quaternius' monsters L1 0.363 against HeterSkinNet's 0.404, their animated
characters 0.151 against 0.167) and farther where every vertex is on one
bone (Kenney's minis 0.971 against 0.814, the dungeon monsters 1.003
against 0.923; on the minis also because SkinningNet does worse than
HeterSkinNet along their derived bones, ``core.skeleton.tails``), so its
mean L1 is behind (0.581 against 0.560) and
HeterSkinNet stays the default (``..methods.DEFAULT_SKIN_METHOD``).
"""

from __future__ import annotations

#: The averaged method's name: ``skin --method``, the panel, ``eval``.
ENSEMBLE = "ensemble"
#: The networks it averages (names in ``.networks.SKIN_NETWORKS``).
ENSEMBLE_MEMBERS = ("heterskinnet", "skinningnet")
ENSEMBLE_LABEL = "HeterSkinNet + SkinningNet"
ENSEMBLE_DESCRIPTION = ("HeterSkinNet and SkinningNet, their weights averaged: nearer the artists' than either "
                        "network alone")


def member_networks(method: str) -> tuple[str, ...]:
    """The networks a learned ``method`` runs: the ensemble's members, or the network itself."""
    return ENSEMBLE_MEMBERS if method == ENSEMBLE else (method,)
