# SPDX-License-Identifier: Apache-2.0
# Run with an installed module first on sys.path: it renders scenes/default, writes a PNG
# and prints which libcambium_imageio.so was loaded (the install's own, not the build's).
#   python3 installed_module.py SOURCE_DIR OUTPUT.png
import os
import sys

import cambium

source, output = sys.argv[1], sys.argv[2]
os.chdir(os.path.join(source, "scenes", "default"))
m = cambium.load("plant.l", "plant.v", materials="plant.mat")
m.render(width=16, height=12, spp=1).write(output)
print(cambium.__file__)
print(next(line.split()[-1] for line in open("/proc/self/maps") if "libcambium_imageio" in line))
