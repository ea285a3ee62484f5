// --device for the generators whose escape counts can run on a Vulkan device (issue #14):
// mandelbulb (--variant fast), julia and mandelbrot2d. The device computes the counts
// (generators/gpu_generate.h); marching cubes, colours and writing stay on the CPU.
#pragma once

#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "core/result.h"
#include "generators/escape_grid.h"
#include "generators/mandelbrot2d.h"
#include "vulkan/context.h"
#include "generators/gpu_generate.h"

namespace dpoint {

struct GenerateDeviceOptions {
  std::string device = "auto";
  bool validate = false;
  std::string counts = "auto";  // auto|capped|full (escape-grid kinds only)
  std::string mesh = "auto";    // auto|host|device: where marching cubes runs (escape-grid kinds only)
};

// `cpu_only_note`: which variants stay on the CPU, for the help text (may be empty).
void addGenerateDeviceOptions(CLI::App& command, GenerateDeviceOptions& options, const std::string& cpu_only_note);

// --counts and --mesh for the escape-grid kinds (mandelbulb, julia): how far the classification
// iterates, and where marching cubes runs.
void addEscapeCountsOption(CLI::App& command, GenerateDeviceOptions& options);
class GenerateDevice;
// Whether the classification runs every count to max_iter: `full`, or `auto` on a GPU (on the
// H100 the GPU's extra iterations cost less than the CPU's finishing; on lavapipe, a CPU, more).
bool fullCounts(const GenerateDeviceOptions& options, const GenerateDevice* device);
// --mesh device without a device to run on (--device none, or auto on a machine without a GPU):
// a usage error naming why.
Status checkMeshDevice(const GenerateDeviceOptions& options, const GenerateDevice* device);
// Whether marching cubes runs on the device: `device` (which implies full counts), or `auto` on a GPU.
bool meshOnDevice(const GenerateDeviceOptions& options, const GenerateDevice* device);

// The device a generation runs its counts on; the functions it hands out hold it alive.
class GenerateDevice : public std::enable_shared_from_this<GenerateDevice> {
 public:
  // nullptr: the CPU. --device none: the CPU. auto: the first GPU (discrete, integrated, virtual;
  // lavapipe is not one) with Vulkan 1.2, shaderFloat64 and shaderInt64, else the CPU; auto never
  // fails. cpu or an index: that device, or the error (kNoDevice: no such device, or it lacks a
  // feature). `cpu_only` (non-empty: why this kind or variant has no device form) makes auto the
  // CPU and an explicit device a usage error naming the reason. `quiet`: no line on stderr naming
  // the device used.
  static Result<std::shared_ptr<GenerateDevice>> open(const GenerateDeviceOptions& options, const std::string& what,
                                                      const std::string& cpu_only, bool quiet);

  EscapePlaneFunction planes(const EscapeKernelParams& kernel, const GridAxis& axis);
  // Where planes() writes in place (GpuEscape::arena); an error gives the heap instead.
  EscapeArena arena();
  // Marching cubes on the device (generators/gpu_mesh.h) of the slabs whose counts it makes as
  // planes(kernel, axis) would; it takes counts of one byte (--max-iter up to 255).
  EscapeSlabMesher mesher(const EscapeKernelParams& kernel);
  // A GPU, not a CPU device such as lavapipe.
  bool isGpu() const;
  PerturbationFunction perturbation();
  // Unless quiet: a line on stderr with the points classified and the GPU time their dispatches
  // took (the classification alone; the generator's functions hold the device until it is done).
  ~GenerateDevice();

 private:
  // With --validate: any message of the layer so far fails the run (kNoDevice), as in render.
  Status checkValidation() const;

  std::unique_ptr<VulkanContext> context_;
  std::unique_ptr<GpuEscape> gpu_;
  std::unique_ptr<GpuMesher> mesher_;  // made at the first slab
  bool validate_ = false;
  bool quiet_ = false;
};

}  // namespace dpoint
