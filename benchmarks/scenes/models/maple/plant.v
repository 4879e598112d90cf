/* Forest species "maple" (SPDX-License-Identifier: Apache-2.0). */
initial color: 1
line style: cylinder
initial line width: 1
projection: parallel
viewpoint: 0.6, 0.25, 1
view reference point: 0, 0, 0
tropism direction: 0, -1, 0
initial elasticity: 0.03
translucency: 12 0.3
