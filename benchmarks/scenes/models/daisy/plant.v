/* Meadow herb "daisy" (SPDX-License-Identifier: Apache-2.0). */
initial color: 4
line style: cylinder
initial line width: 0.01
projection: parallel
viewpoint: 0.6, 0.25, 1
view reference point: 0, 0, 0
translucency: 5 0.35
