# Sourced by the bench/scripts/gpu_*.sh scripts on the GPU machine (device tool: NVIDIA H100/H200,
# Ubuntu 24.04, no package registry): unpacks the carried Vulkan loader and validation layer
# (.gl/, Debian packages: libvulkan1, libglvnd0, libglx0, libegl1 and friends, and
# vulkan-validationlayers for the gtest suites that turn the layer on; `apt-get download` each),
# points the loader at NVIDIA's driver and the dynamic linker at the carried libraries
# (.gpu/lib), and names the output folder.
for f in .gl/*.deb; do dpkg -x "$f" /; done
ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
export LD_LIBRARY_PATH=$PWD/.gpu/lib
out=${OUT:-/tmp/out}
nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader | tee "$out/gpu.txt"
