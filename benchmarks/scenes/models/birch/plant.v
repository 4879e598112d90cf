/* Forest species "birch" (SPDX-License-Identifier: Apache-2.0). */
initial color: 11
line style: cylinder
initial line width: 1
projection: parallel
viewpoint: 0.6, 0.25, 1
view reference point: 0, 0, 0
tropism direction: 0, -1, 0
initial elasticity: 0.12
translucency: 6 0.35
