/* Cambium's default scene view (SPDX-License-Identifier: Apache-2.0). */
angle factor: 8
initial color: 1
color increment: 1
line style: cylinder
initial line width: 1
line width increment: 0.1

projection: parallel
viewpoint: 0.6, 0.25, 1
view reference point: 0, 0, 0
scale factor: 0.92

/* A warm key light from the upper right and a weak cool fill from the left. */
light: V: 1 0.8 0.9 D: 1.0 0.95 0.85
light: V: -1 0.3 0.4 D: 0.25 0.3 0.4

/* Cambium extension: leaves pass a third of their diffuse light through. */
translucency: 5 0.35
