"""What every generated character draws from its seed besides its shape:
its overall size, whether it has a root bone, and which optional pieces it
gets. The ranges of each kind's proportions live with the kind
(:mod:`.kinds`)."""

from __future__ import annotations

#: Probability that a character gets a non-deforming ``root`` bone at the floor.
ROOT_BONE_PROBABILITY = 0.5

#: Probability of each optional piece, per character of a kind that can have it.
ACCESSORY_PROBABILITY = {
    "eyes": 0.8,
    "fingers": 0.5,
    "breasts": 0.2,
    "helmet": 0.2,
    "hat": 0.2,
    "sword": 0.3,
    "shield": 0.2,
    "belt": 0.35,
    "buttons": 0.35,
    "backpack": 0.2,
    "skirt": 0.3,
    "cape": 0.25,
    "ponytail": 0.25,
    "garment_bones": 0.5,  # skirt or cape driven by its own bones rather than by the body
    "ears": 0.6,
    "horns": 0.3,
    "collar": 0.3,
    "blanket": 0.3,
    "saddle": 0.2,
    "spikes": 0.35,
    "antennae": 0.7,
    "insect_wings": 0.5,
    "stinger": 0.3,
    "lure": 0.3,
    "door_frame": 0.6,
    "door_handle": 0.7,
    "lamp_upper_arm": 0.6,
    "chest_lock": 0.5,
}

#: Overall size of each kind, metres: the height of bipeds (tailed humanoids
#: too) and birds, the largest extent of many-legged creatures and long
#: chains, the length front to back of the others.
SIZE_RANGE = {
    "biped": (0.4, 2.4),
    "quadruped": (0.3, 3.0),
    "multileg": (0.05, 2.0),
    "bird": (0.15, 1.6),
    "dragon": (1.0, 8.0),
    "tailed": (0.3, 6.0),
    "long_chain": (0.5, 6.0),
    "fish": (0.15, 8.0),
}
