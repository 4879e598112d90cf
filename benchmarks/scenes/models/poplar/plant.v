/* Forest species "poplar" (SPDX-License-Identifier: Apache-2.0). */
initial color: 1
line style: cylinder
initial line width: 1
projection: parallel
viewpoint: 0.6, 0.25, 1
view reference point: 0, 0, 0
translucency: 6 0.35
