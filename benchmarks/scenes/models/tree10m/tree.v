/* Benchmark tree's view (SPDX-License-Identifier: Apache-2.0). */
initial color: 1
line style: cylinder
initial line width: 1
projection: parallel
viewpoint: 0.6, 0.25, 1
view reference point: 0, 0, 0
scale factor: 0.95

/* Twigs droop under their weight. */
tropism direction: 0, -1, 0
initial elasticity: 0.06

light: V: 1 0.8 0.9 D: 1.0 0.95 0.85
light: V: -1 0.3 0.4 D: 0.25 0.3 0.4
