/* The grass tuft's view (SPDX-License-Identifier: Apache-2.0). */
angle factor: 8
initial color: 1
initial line width: 0.04
line style: cylinder
projection: parallel
viewpoint: 0, 0.3, 1
view reference point: 0, 0.5, 0
translucency: 1 0.3
