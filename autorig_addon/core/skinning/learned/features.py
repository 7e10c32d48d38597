"""What the skinning networks see: one :class:`SkinGraph` per character.

All three networks predict, for every vertex, a distribution over its
:data:`CANDIDATE_BONES` nearest deform bones (RigNet's candidate set), as a
correction of a geometric prior. The inputs they share, built here once for
training (from cached samples) and inference (inside Blender):

* **per-(vertex, bone) features**, the ones that generalise from few
  examples: where the bone lies relative to the vertex, the distance through
  the shape and the straight one (their ratio says whether something stands
  between them), how much farther the bone is than the vertex's nearest,
  the weight of the prior the network corrects (our geometric method or
  Blender-style bone heat: each network spec's ``prior``);
* **per-vertex features**: position and normal;
* **per-bone features**: head, tail, direction, length, leaf flag, depth;
* **graphs**: the mesh one-ring and geodesic balls (RigNet's GMEdgeConv),
  the candidate vertex-bone pairs (HeterSkinNet) and the hierarchy between
  deform bones (SkinningNet's skeleton stream).

The character must already be in the normalised frame of
:func:`...dataset.normalise.normalise` (z up, facing -y, left at +x, largest
side 1), so lengths are fractions of the character's size. The layouts of
the feature columns are named below; the columns listed in the
``*_VECTORS`` tuples are 3-vectors, which augmentation turns and mirrors.
"""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from ...geometry.normals import vertex_normals
from ...geometry.segments import paired_segment_parameters
from ...nn.graph import geodesic_ball_edges, hierarchy_edges, mesh_edges, vertex_bone_edges, with_self_loops
from ...skeleton.hierarchy import descendant_counts
from ...types import Mesh, Skeleton

#: Bones a vertex may take weight from: its nearest by the network's
#: distance (RigNet uses 5). On the 53 characters the 5 nearest bones by
#: volumetric geodesic distance carry 98.6 % of the artists' weight (the 4
#: nearest 97.3 %, the 6 nearest 99.1 %).
CANDIDATE_BONES = 5
#: Radius of the geodesic balls (fraction of the character's largest side):
#: RigNet's GMEdgeConv pools over such balls to see past the one-ring.
GEODESIC_BALL_RADIUS = 0.04
#: Neighbours kept per geodesic ball (the nearest along the surface).
GEODESIC_BALL_NEIGHBOURS = 12
#: Floor of distances in ratios and inverses (fraction of the character's
#: size), so a vertex on a bone does not divide by zero.
DISTANCE_FLOOR = 1e-3
#: Floor of the prior weight inside its logarithm: a bone the prior gives
#: nothing still gets a finite score the network can raise.
PRIOR_FLOOR = 1e-3

#: Per-vertex columns: position (0:3), normal (3:6).
VERTEX_FEATURES = 6
VERTEX_VECTORS = (0, 3)
#: Per-(vertex, bone) columns: head - vertex (0:3), tail - vertex (3:6),
#: closest bone point - vertex (6:9), network distance, straight distance,
#: log(network / straight), log(distance / the vertex's nearest),
#: candidate rank / (K - 1), position along the bone (0 head, 1 tail), bone
#: length, leaf flag, prior weight, log prior, cosine between the normal and
#: the direction to the bone.
PAIR_FEATURES = 20
PAIR_VECTORS = (0, 3, 6)
#: Per-bone columns: head (0:3), tail (3:6), unit direction (6:9), length,
#: leaf flag, depth / deepest depth, number of children.
BONE_FEATURES = 13
BONE_VECTORS = (0, 3, 6)


@dataclass(frozen=True)
class SkinGraph:
    """The inputs of the skinning networks for one character (``n``
    vertices, ``d`` deform bones, ``K`` = :data:`CANDIDATE_BONES`).

    Attributes
    ----------
    vertex_features : (n, VERTEX_FEATURES) float32
    pair_features : (n, K, PAIR_FEATURES) float32, zero where not ``valid``
    candidates : (n, K) int64, deform-bone index of each candidate, nearest
        first (0 where not ``valid``)
    valid : (n, K) bool, False for the missing candidates of a skeleton
        with fewer than K deform bones
    prior : (n, K) float32, the prior's weights of the candidates
    bone_features : (d, BONE_FEATURES) float32
    mesh_edges : (2, e) int64, one-ring with self loops
    ball_edges : (2, e') int64, geodesic balls with self loops
    bone_edges : (2, h) int64, deform-bone hierarchy both ways, with self loops
    """

    vertex_features: np.ndarray
    pair_features: np.ndarray
    candidates: np.ndarray
    valid: np.ndarray
    prior: np.ndarray
    bone_features: np.ndarray
    mesh_edges: np.ndarray
    ball_edges: np.ndarray
    bone_edges: np.ndarray

    @property
    def vertex_count(self) -> int:
        return len(self.vertex_features)

    @property
    def bone_count(self) -> int:
        return len(self.bone_features)

    def arrays(self) -> dict:
        """The fields as a ``{name: array}`` dict (to save as ``.npz``)."""
        return {field.name: getattr(self, field.name) for field in fields(self)}

    @classmethod
    def from_arrays(cls, arrays) -> "SkinGraph":
        """Inverse of :meth:`arrays` (also reads an open ``.npz``)."""
        return cls(**{field.name: np.asarray(arrays[field.name]) for field in fields(cls)})


def skin_graph(mesh: Mesh, skeleton: Skeleton, distances: np.ndarray, prior: np.ndarray) -> SkinGraph:
    """The network inputs of a normalised character.

    Parameters
    ----------
    mesh : Mesh in the normalised frame (see the module docstring)
    skeleton : Skeleton in the same frame; only its deform bones are used
    distances : (n, d) float array, vertex-to-deform-bone distances through
        the shape (volumetric geodesic or HollowDist), same frame
    prior : (n, d) float array, the prior's weights (a network spec's ``prior``)

    Returns
    -------
    SkinGraph
    """
    bones = skeleton.deform_subset()
    heads, tails = bones.joints, bones.tails
    vertices = np.asarray(mesh.vertices, dtype=np.float64)
    distances = np.asarray(distances, dtype=np.float64)
    normals = vertex_normals(vertices, mesh.triangles)
    candidates, valid = _candidate_bones(distances)

    pair = np.zeros(candidates.shape + (PAIR_FEATURES,))
    rows = np.arange(len(vertices))[:, None]
    head_offset = heads[candidates] - vertices[:, None]
    tail_offset = tails[candidates] - vertices[:, None]
    along = _parameters_along(vertices, heads, tails, candidates)
    closest_offset = head_offset + along[..., None] * (tail_offset - head_offset)
    straight = np.linalg.norm(closest_offset, axis=2)
    through = distances[rows, candidates]
    nearest = distances.min(axis=1, keepdims=True)
    lengths = np.linalg.norm(tails - heads, axis=1)
    leaves = descendant_counts(bones.parents) == 0
    candidate_prior = np.asarray(prior, dtype=np.float64)[rows, candidates]
    pair[..., 0:3] = head_offset
    pair[..., 3:6] = tail_offset
    pair[..., 6:9] = closest_offset
    pair[..., 9] = through
    pair[..., 10] = straight
    pair[..., 11] = np.log((through + DISTANCE_FLOOR) / (straight + DISTANCE_FLOOR))
    pair[..., 12] = np.log((through + DISTANCE_FLOOR) / (nearest + DISTANCE_FLOOR))
    pair[..., 13] = np.arange(candidates.shape[1]) / max(CANDIDATE_BONES - 1, 1)
    pair[..., 14] = along
    pair[..., 15] = lengths[candidates]
    pair[..., 16] = leaves[candidates]
    pair[..., 17] = candidate_prior
    pair[..., 18] = np.log(candidate_prior + PRIOR_FLOOR)
    pair[..., 19] = np.einsum("nkc,nc->nk", closest_offset, normals) / np.maximum(straight, DISTANCE_FLOOR)
    pair[~valid] = 0.0

    prior_rows = np.where(valid, candidate_prior, 0.0)
    return SkinGraph(
        vertex_features=np.concatenate([vertices, normals], axis=1).astype(np.float32),
        pair_features=pair.astype(np.float32),
        candidates=np.where(valid, candidates, 0).astype(np.int64),
        valid=valid,
        prior=prior_rows.astype(np.float32),
        bone_features=_bone_features(bones, leaves, lengths).astype(np.float32),
        mesh_edges=mesh_edges(mesh.triangles, len(vertices), self_loops=True),
        ball_edges=geodesic_ball_edges(vertices, mesh.triangles, GEODESIC_BALL_RADIUS,
                                       max_neighbours=GEODESIC_BALL_NEIGHBOURS, self_loops=True)[0],
        bone_edges=with_self_loops(hierarchy_edges(bones.parents), len(heads)),
    )


def candidate_targets(graph: SkinGraph, weights: np.ndarray) -> np.ndarray:
    """(n, K) float32: the reference ``weights`` (n, d) of each vertex's
    candidates, renormalised over them; rows with no weight on any
    candidate are zero (training leaves them out)."""
    rows = np.arange(graph.vertex_count)[:, None]
    picked = np.where(graph.valid, np.asarray(weights, dtype=np.float64)[rows, graph.candidates], 0.0)
    totals = picked.sum(axis=1, keepdims=True)
    return np.divide(picked, totals, out=np.zeros_like(picked), where=totals > 0).astype(np.float32)


def _candidate_bones(distances: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(n, K) nearest bones, nearest first (ties to the lower index), and
    which of the K slots hold a bone."""
    vertex_count, bone_count = distances.shape
    kept = min(CANDIDATE_BONES, bone_count)
    candidates = np.zeros((vertex_count, CANDIDATE_BONES), dtype=np.int64)
    candidates[:, :kept] = vertex_bone_edges(distances, CANDIDATE_BONES)[0][1].reshape(vertex_count, kept)
    valid = np.zeros((vertex_count, CANDIDATE_BONES), dtype=bool)
    valid[:, :kept] = True
    return candidates, valid


def _parameters_along(vertices: np.ndarray, heads: np.ndarray, tails: np.ndarray, candidates: np.ndarray) -> np.ndarray:
    """(n, K) position of each vertex's closest point along each candidate
    bone, 0 at the head and 1 at the tail."""
    along = np.empty(candidates.shape)
    for slot in range(candidates.shape[1]):
        chosen = candidates[:, slot]
        along[:, slot] = paired_segment_parameters(vertices, heads[chosen], tails[chosen])
    return along


def _bone_features(bones: Skeleton, leaves: np.ndarray, lengths: np.ndarray) -> np.ndarray:
    heads, tails = bones.joints, bones.tails
    direction = (tails - heads) / np.maximum(lengths, 1e-12)[:, None]
    depth = np.zeros(len(heads))
    for bone, parent in enumerate(bones.parents):  # parents come first
        depth[bone] = depth[parent] + 1 if parent >= 0 else 0
    children = np.bincount(bones.parents[bones.parents >= 0], minlength=len(heads))
    return np.column_stack([heads, tails, direction, lengths, leaves, depth / max(depth.max(), 1.0), children])
