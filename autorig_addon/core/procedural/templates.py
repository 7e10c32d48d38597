"""Skeleton templates for the procedural character generator.

Joint layouts baked from the Rigify metarigs that ship inside Blender
(``scripts/addons_core/rigify/metarigs/``: ``Basic/basic_human.py``,
``Basic/basic_quadruped.py``, ``Animals/bird.py``, ``Animals/shark.py``), so
the generator never imports Rigify or bpy. Baking kept, for each metarig,
the centre bones and the left (``.L``) bones of the body; the generator makes
the right side by mirroring across x = 0. Left out: Rigify helper and face
bones (pelvis, tongue, skull, toe digits, lip corners, neck feathers), and the
quadruped's tail and chest bones (the generator grows its own tail). Renamed
for Blender's suffix convention: ``beak_001.B`` -> ``beak.001.B``,
``side_fin.L.001`` -> ``side_fin.001.L``. Centre bones were snapped to x = 0
exactly (the metarigs store ``-0.0``).

Each table row is ``(name, parent, head, tail, deform)``: positions in metres
in the metarig's own frame (character faces -y, z up), parents listed before
children, ``deform`` False for control bones (Rigify's foot-roll heel and
shark jaw master).
"""

from __future__ import annotations

#: Rigify "Basic Human" (1.98 m tall, arms in a slight A-pose).
HUMAN = (
    ('spine', None, (0.0000, 0.0552, 1.0099), (0.0000, 0.0172, 1.1573), True),
    ('spine.001', 'spine', (0.0000, 0.0172, 1.1573), (0.0000, 0.0004, 1.2929), True),
    ('thigh.L', 'spine', (0.0980, 0.0124, 1.0720), (0.0980, -0.0286, 0.5372), True),
    ('spine.002', 'spine.001', (0.0000, 0.0004, 1.2929), (0.0000, 0.0059, 1.4657), True),
    ('shin.L', 'thigh.L', (0.0980, -0.0286, 0.5372), (0.0980, 0.0162, 0.0852), True),
    ('spine.003', 'spine.002', (0.0000, 0.0059, 1.4657), (0.0000, 0.0114, 1.6582), True),
    ('foot.L', 'shin.L', (0.0980, 0.0162, 0.0852), (0.0980, -0.0934, 0.0167), True),
    ('spine.004', 'spine.003', (0.0000, 0.0114, 1.6582), (0.0000, -0.0130, 1.7197), True),
    ('shoulder.L', 'spine.003', (0.0183, -0.0684, 1.6051), (0.1694, 0.0205, 1.6050), True),
    ('breast.L', 'spine.003', (0.1184, 0.0485, 1.4596), (0.1184, -0.0907, 1.4596), True),
    ('toe.L', 'foot.L', (0.0980, -0.0934, 0.0167), (0.0980, -0.1606, 0.0167), True),
    ('heel.02.L', 'foot.L', (0.0600, 0.0459, 0.0000), (0.1400, 0.0459, 0.0000), False),
    ('spine.005', 'spine.004', (0.0000, -0.0130, 1.7197), (0.0000, -0.0247, 1.7813), True),
    ('upper_arm.L', 'shoulder.L', (0.1953, 0.0267, 1.5846), (0.4424, 0.0885, 1.4491), True),
    ('spine.006', 'spine.005', (0.0000, -0.0247, 1.7813), (0.0000, -0.0247, 1.9796), True),
    ('forearm.L', 'upper_arm.L', (0.4424, 0.0885, 1.4491), (0.6594, 0.0492, 1.3061), True),
    ('hand.L', 'forearm.L', (0.6594, 0.0492, 1.3061), (0.7234, 0.0412, 1.2585), True),
)

#: Rigify "Basic Quadruped" without pelvis, chest and tail bones.
QUADRUPED = (
    ('spine.004', None, (0.0000, 0.4418, 0.7954), (0.0000, 0.3546, 0.8059), True),
    ('spine.005', 'spine.004', (0.0000, 0.3546, 0.8059), (0.0000, 0.1803, 0.7782), True),
    ('spine.006', 'spine.005', (0.0000, 0.1803, 0.7782), (0.0000, 0.0319, 0.7731), True),
    ('thigh.L', 'spine.005', (0.1249, 0.3419, 0.7379), (0.1249, 0.2712, 0.4731), True),
    ('spine.007', 'spine.006', (0.0000, 0.0319, 0.7731), (0.0000, -0.0980, 0.7945), True),
    ('shin.L', 'thigh.L', (0.1249, 0.2712, 0.4731), (0.1114, 0.4766, 0.2473), True),
    ('spine.008', 'spine.007', (0.0000, -0.0980, 0.7945), (0.0000, -0.3618, 0.8375), True),
    ('foot.L', 'shin.L', (0.1114, 0.4766, 0.2473), (0.1088, 0.4138, 0.0411), True),
    ('spine.009', 'spine.008', (0.0000, -0.3618, 0.8375), (0.0000, -0.4253, 0.8585), True),
    ('shoulder.L', 'spine.008', (0.0596, -0.2578, 0.8876), (0.1249, -0.3418, 0.7153), True),
    ('toe.L', 'foot.L', (0.1088, 0.4138, 0.0411), (0.1088, 0.2808, 0.0000), True),
    ('spine.010', 'spine.009', (0.0000, -0.4253, 0.8585), (0.0000, -0.4888, 0.8796), True),
    ('front_thigh.L', 'shoulder.L', (0.1249, -0.3161, 0.6902), (0.1249, -0.2245, 0.4418), True),
    ('spine.011', 'spine.010', (0.0000, -0.4888, 0.8796), (0.0000, -0.6590, 0.9809), True),
    ('front_shin.L', 'front_thigh.L', (0.1249, -0.2245, 0.4418), (0.1114, -0.2147, 0.1698), True),
    ('front_foot.L', 'front_shin.L', (0.1114, -0.2147, 0.1698), (0.1088, -0.2462, 0.0411), True),
    ('front_toe.L', 'front_foot.L', (0.1088, -0.2462, 0.0411), (0.1088, -0.3707, 0.0000), True),
)

#: Rigify "Bird" body, wings, feathers, legs and beak (0.2 m tall).
BIRD = (
    ('spine.003', None, (0.0000, 0.0451, 0.0845), (0.0000, 0.0192, 0.0888), True),
    ('spine.002', 'spine.003', (0.0000, 0.0451, 0.0845), (0.0000, 0.0757, 0.0880), True),
    ('spine.004', 'spine.003', (0.0000, 0.0192, 0.0888), (0.0000, -0.0106, 0.0979), True),
    ('spine.001', 'spine.002', (0.0000, 0.0757, 0.0880), (0.0000, 0.1039, 0.0907), True),
    ('spine.005', 'spine.004', (0.0000, -0.0106, 0.0979), (0.0000, -0.0298, 0.1158), True),
    ('thigh.L', 'spine.004', (0.0149, 0.0063, 0.0739), (0.0149, 0.0143, 0.0391), True),
    ('spine', 'spine.001', (0.0000, 0.1039, 0.0907), (0.0000, 0.1371, 0.0894), True),
    ('shoulder.L', 'spine.005', (0.0014, -0.0217, 0.0893), (0.0076, -0.0020, 0.1179), True),
    ('spine.006', 'spine.005', (0.0000, -0.0298, 0.1158), (0.0000, -0.0417, 0.1348), True),
    ('shin.L', 'thigh.L', (0.0149, 0.0143, 0.0391), (0.0149, 0.0015, 0.0074), True),
    ('t_feather.L', 'spine', (0.0112, 0.1017, 0.0907), (0.0167, 0.1345, 0.0894), True),
    ('Wing.L', 'shoulder.L', (0.0089, 0.0141, 0.1157), (0.0485, 0.0107, 0.1163), True),
    ('neck.001', 'spine.006', (0.0000, -0.0417, 0.1348), (0.0000, -0.0458, 0.1429), True),
    ('foot.L', 'shin.L', (0.0149, 0.0015, 0.0074), (0.0149, -0.0033, 0.0045), True),
    ('Wing.001.L', 'Wing.L', (0.0485, 0.0107, 0.1163), (0.0919, 0.0021, 0.1191), True),
    ('w_feather.004.L', 'Wing.L', (0.0382, 0.0253, 0.1081), (0.0553, 0.0878, 0.0901), True),
    ('neck.002', 'neck.001', (0.0000, -0.0458, 0.1429), (0.0000, -0.0483, 0.1498), True),
    ('toe.L', 'foot.L', (0.0149, -0.0033, 0.0045), (0.0149, -0.0404, 0.0006), True),
    ('Wing.002.L', 'Wing.001.L', (0.0919, 0.0021, 0.1191), (0.2128, 0.0178, 0.1159), True),
    ('w_feather.003.L', 'Wing.001.L', (0.0754, 0.0212, 0.1122), (0.1342, 0.0830, 0.0901), True),
    ('head', 'neck.002', (0.0000, -0.0483, 0.1498), (0.0000, -0.1026, 0.1815), True),
    ('w_feather.001.L', 'Wing.002.L', (0.1595, -0.0062, 0.1163), (0.2489, -0.0055, 0.1224), True),
    ('w_feather.002.L', 'Wing.002.L', (0.1218, 0.0331, 0.1099), (0.1812, 0.0495, 0.1068), True),
    ('beak.001.T', 'head', (0.0000, -0.0703, 0.1580), (0.0000, -0.0927, 0.1597), True),
    ('beak.001.B', 'head', (0.0000, -0.0703, 0.1556), (0.0000, -0.0914, 0.1555), True),
    ('eye.L', 'head', (0.0055, -0.0647, 0.1615), (0.0198, -0.0675, 0.1615), True),
    ('beak.002.T', 'beak.001.T', (0.0000, -0.0927, 0.1597), (0.0000, -0.1131, 0.1533), True),
    ('beak.002.B', 'beak.001.B', (0.0000, -0.0914, 0.1555), (0.0000, -0.1084, 0.1519), True),
)

#: Rigify "Shark" body, fins, eyes and jaw (2.1 m long).
SHARK = (
    ('spine.003', None, (0.0000, 0.3182, 0.4031), (0.0000, 0.0152, 0.3904), True),
    ('spine.002', 'spine.003', (0.0000, 0.3182, 0.4031), (0.0000, 0.7152, 0.4305), True),
    ('spine.008', 'spine.003', (0.0000, 0.0152, 0.3904), (0.0000, -0.3259, 0.3967), True),
    ('spine.001', 'spine.002', (0.0000, 0.7152, 0.4305), (0.0000, 1.0816, 0.4540), True),
    ('spine.004', 'spine.008', (0.0000, -0.3259, 0.3967), (0.0000, -0.5947, 0.4044), True),
    ('chest_fin.Bot.L', 'spine.008', (0.0889, 0.2605, 0.2866), (0.1731, 0.3299, 0.1901), True),
    ('spine', 'spine.001', (0.0000, 1.0816, 0.4540), (0.0000, 1.3362, 0.4776), True),
    ('mid_fin.Top', 'spine.001', (0.0000, 0.7296, 0.5396), (0.0000, 0.7709, 0.6351), True),
    ('mid_fin.Bot', 'spine.001', (0.0000, 0.7296, 0.3505), (0.0000, 0.8233, 0.2684), True),
    ('spine.005', 'spine.004', (0.0000, -0.5947, 0.4044), (0.0000, -1.2084, 0.4328), True),
    ('top_fin', 'spine.004', (0.0000, -0.2777, 0.5550), (0.0000, -0.1962, 0.7053), True),
    ('back_fin.T.Bk', 'spine', (0.0000, 1.2501, 0.5345), (0.0000, 1.5211, 0.7594), True),
    ('back_fin.B.Bk', 'spine', (0.0000, 1.2305, 0.4158), (0.0000, 1.3289, 0.2452), True),
    ('spine.006', 'spine.005', (0.0000, -1.2084, 0.4328), (0.0000, -1.5634, 0.4275), True),
    ('shoulder.L', 'spine.005', (0.0729, -0.9648, 0.3756), (0.2649, -0.9648, 0.3157), True),
    ('top_fin.001', 'top_fin', (0.0000, -0.1962, 0.7053), (0.0000, -0.1362, 0.8158), True),
    ('back_fin.T.001.Bk', 'back_fin.T.Bk', (0.0000, 1.5211, 0.7594), (0.0000, 1.7667, 0.9633), True),
    ('back_fin.B.001.Bk', 'back_fin.B.Bk', (0.0000, 1.3289, 0.2452), (0.0000, 1.3818, 0.1513), True),
    ('spine.007', 'spine.006', (0.0000, -1.5634, 0.4275), (0.0000, -2.0661, 0.4364), True),
    ('side_fin.L', 'shoulder.L', (0.2140, -0.9624, 0.2213), (0.5220, -0.9078, -0.1343), True),
    ('back_fin.T.002.Bk', 'back_fin.T.001.Bk', (0.0000, 1.7667, 0.9633), (0.0000, 1.9489, 1.1145), True),
    ('eye.L', 'spine.007', (0.1405, -1.6860, 0.4161), (0.3684, -1.6810, 0.4156), True),
    ('jaw.master', 'spine.007', (0.0000, -1.5791, 0.2788), (0.0000, -1.9421, 0.3386), False),
    ('side_fin.001.L', 'side_fin.L', (0.5220, -0.9078, -0.1343), (0.7928, -0.7598, -0.4802), True),
    ('jaw', 'jaw.master', (0.0000, -1.5791, 0.2788), (0.0000, -1.7326, 0.3041), True),
    ('jaw.001', 'jaw', (0.0000, -1.7326, 0.3041), (0.0000, -1.8860, 0.3294), True),
)

#: Template tables by name.
TEMPLATES = {"human": HUMAN, "quadruped": QUADRUPED, "bird": BIRD, "shark": SHARK}
