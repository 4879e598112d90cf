/* The meadow flower's view (SPDX-License-Identifier: Apache-2.0). */
angle factor: 8
initial color: 1
initial line width: 0.05
line style: cylinder
projection: parallel
viewpoint: 0, 0.3, 1
view reference point: 0, 1.5, 0
light: V: 1 0.8 0.9 D: 1.0 0.95 0.85
translucency: 2 0.3
translucency: 3 0.3
