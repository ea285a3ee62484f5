#include "cli/cli_device.h"

#include <cstdio>

#include "cli/cli_check.h"

namespace dpoint {

void addGenerateDeviceOptions(CLI::App& command, GenerateDeviceOptions& options, const std::string& cpu_only_note) {
  command
      .add_option("--device", options.device,
                  "Where the escape counts run: auto (a GPU with fp64 if there is one, else the CPU), none (the "
                  "CPU),\ncpu (lavapipe) or an index from `dpoint devices`; the counts are the CPU's bit for bit. "
                  "Marching cubes,\nthe noise colours and a .ply's rows are made there too on a GPU (--mesh), and the rows written as\nthey come" +
                      (cpu_only_note.empty() ? std::string() : ".\n" + cpu_only_note))
      ->default_val("auto");
  command.add_flag("--validate", options.validate,
                   "With a device: enable the Khronos validation layer; any message fails the run");
}

void addEscapeCountsOption(CLI::App& command, GenerateDeviceOptions& options) {
  command
      .add_option("--counts", options.counts,
                  "How far the classification iterates: capped (just past the level; the points near the surface\n"
                  "are then finished to --max-iter on the CPU), full (every point to --max-iter), auto (full on\n"
                  "a GPU, capped on the CPU and on lavapipe). The output is the same bit for bit")
      ->check(oneOf("--counts", {"auto", "capped", "full"}))
      ->default_val("auto");
  command
      .add_option("--mesh", options.mesh,
                  "Where marching cubes runs: host (the CPU's cores), device (the --device that counts; implies\n"
                  "--counts full, wherever the mesh reads a count; counts of two bytes, past --max-iter 255, are\n"
                  "meshed on the host), auto (device on a GPU, host on the CPU and on lavapipe). The output is the\n"
                  "same bit for bit")
      ->check(oneOf("--mesh", {"auto", "host", "device"}))
      ->default_val("auto");
}

bool fullCounts(const GenerateDeviceOptions& options, const GenerateDevice* device) {
  return options.counts == "full" || (options.counts == "auto" && device && device->isGpu()) ||
         meshOnDevice(options, device);
}

Status checkMeshDevice(const GenerateDeviceOptions& options, const GenerateDevice* device) {
  if (options.mesh != "device" || device) return okStatus();
  return Error{"--mesh device: no device makes the counts (--device " + options.device +
                   (options.device == "auto" ? " found no GPU with shaderFloat64 and shaderInt64, or the kind runs on the CPU" : "") +
                   "); --device cpu runs them on lavapipe",
               ExitCode::kUsage};
}

bool meshOnDevice(const GenerateDeviceOptions& options, const GenerateDevice* device) {
  return device && (options.mesh == "device" || (options.mesh == "auto" && device->isGpu()));
}

bool GenerateDevice::isGpu() const { return context_->facts.type != "cpu"; }

Result<std::shared_ptr<GenerateDevice>> GenerateDevice::open(const GenerateDeviceOptions& options,
                                                            const std::string& what, const std::string& cpu_only,
                                                            bool quiet) {
  const std::string& wanted = options.device;
  if (wanted == "none") return std::shared_ptr<GenerateDevice>();
  std::string index = wanted;
  if (wanted == "auto") {
    if (!cpu_only.empty()) return std::shared_ptr<GenerateDevice>();
    Result<std::vector<DeviceFacts>> all = listDevices();
    if (!all) return std::shared_ptr<GenerateDevice>();  // no loader or driver: the CPU
    index.clear();
    for (const DeviceFacts& f : *all) {
      const bool gpu = f.type == "discrete" || f.type == "integrated" || f.type == "virtual";
      if (gpu && f.vulkan12 && f.has_graphics_queue && gpuGenerateUsable(f)) {
        index = std::to_string(f.index);
        break;
      }
    }
    if (index.empty()) return std::shared_ptr<GenerateDevice>();
  } else if (!cpu_only.empty()) {
    return Error{"--device " + wanted + ": " + cpu_only, ExitCode::kUsage};
  }
  std::shared_ptr<GenerateDevice> device(new GenerateDevice());
  device->validate_ = options.validate;
  ContextOptions context_options{index, options.validate};
  context_options.transfer_queue = true;  // the mesh's rows are copied out there (generators/gpu_mesh.h)
  Result<std::unique_ptr<VulkanContext>> context = VulkanContext::create(context_options);
  if (!context) return context.error();
  device->context_ = std::move(*context);
  Result<std::unique_ptr<GpuEscape>> gpu = GpuEscape::create(*device->context_);
  if (!gpu) return Error{"--device " + wanted + ": " + gpu.error().message, gpu.error().code};
  device->gpu_ = std::move(*gpu);
  if (Status s = device->checkValidation(); !s) return s.error();
  device->quiet_ = quiet;
  if (!quiet) {
    const DeviceFacts& f = device->context_->facts;
    std::fprintf(stderr, "dpoint: %s escape counts on %s (%s, driver %s)\n", what.c_str(), f.name.c_str(),
                 f.type.c_str(), formatDriverVersion(f.vendor_id, f.driver_version).c_str());
  }
  return device;
}

GenerateDevice::~GenerateDevice() {
  if (quiet_ || !gpu_ || gpu_->pointsDone() == 0 || !(gpu_->gpuMs() > 0.0)) return;
  std::fprintf(stderr,
               "dpoint: escape counts of %llu points in %.1f ms of GPU time (%.3g points/s); the host waited %.0f ms "
               "for them and copied them out in %.0f ms\n",
               static_cast<unsigned long long>(gpu_->pointsDone()), gpu_->gpuMs(),
               static_cast<double>(gpu_->pointsDone()) / (gpu_->gpuMs() * 1e-3), gpu_->waitMs(), gpu_->copyMs());
  if (mesher_ && mesher_->times().total() > 0.0) {
    const GpuMesher::Times& t = mesher_->times();
    std::fprintf(stderr,
                 "dpoint: marching cubes on the device in %.1f ms of GPU time (counting and scanning %.1f, vertices "
                 "%.1f, triangles %.1f, %s %.1f)\n",
                 t.total(), t.scan, t.vertices, t.triangles,
                 t.copied_beside ? "the rows (copied across on the transfer queue, beside)" : "copying them across", t.copy);
  }
}

Status GenerateDevice::checkValidation() const {
  if (!validate_ || context_->validationMessages().empty()) return okStatus();
  const std::vector<std::string>& messages = context_->validationMessages();
  return Error{std::to_string(messages.size()) + " Vulkan validation message(s), the first: " + messages.front(),
               ExitCode::kNoDevice};
}

EscapePlaneFunction GenerateDevice::planes(const EscapeKernelParams& kernel, const GridAxis& axis) {
  // The axis values are made at the first call, once the generator has checked the resolution.
  auto values = std::make_shared<std::vector<double>>();
  return [self = shared_from_this(), kernel, axis, values](int first, int count, int limit, uint8_t* counts) -> Status {
    if (values->empty())
      for (int i = 0; i < axis.resolution; ++i) values->push_back(axis.value(i));
    if (Status s = self->gpu_->escapePlanes(kernel, *values, first, count, limit, counts); !s) return s;
    return self->checkValidation();
  };
}

EscapeArena GenerateDevice::arena() {
  return [self = shared_from_this()](uint64_t bytes) -> uint8_t* {
    Result<uint8_t*> memory = self->gpu_->arena(bytes);
    return memory ? *memory : nullptr;
  };
}

EscapeSlabMesher GenerateDevice::mesher(const EscapeKernelParams& kernel) {
  EscapeSlabMesher mesher;
  mesher.takes = &GpuMesher::supports;
  mesher.mesh = [self = shared_from_this(), kernel](const EscapeSlab& slab, const EscapeSlab* next) -> Result<McSlabView> {
    if (!self->mesher_) {
      Result<std::unique_ptr<GpuMesher>> made = GpuMesher::create(*self->context_);
      if (!made) return made.error();
      self->mesher_ = std::move(*made);
    }
    Result<McSlabView> mesh = meshSlabOnDevice(*self->gpu_, *self->mesher_, kernel, slab, next);
    if (!mesh) return mesh.error();
    if (Status s = self->checkValidation(); !s) return s.error();
    return mesh;
  };
  mesher.reserve = [self = shared_from_this()](uint64_t vertices, uint64_t triangles, bool colors, size_t row_bytes) {
    // After the first mesh call, which made the mesher.
    return self->mesher_ ? self->mesher_->reserve(vertices, triangles, colors, row_bytes) : okStatus();
  };
  return mesher;
}

PerturbationFunction GenerateDevice::perturbation() {
  return [self = shared_from_this()](const std::vector<glm::dvec2>& orbit, const std::vector<double>& dcx,
                                    const std::vector<double>& dcy, int max_iter, uint32_t* counts,
                                    EscapeTail* tails) -> Status {
    if (Status s = self->gpu_->perturbation(orbit, dcx, dcy, max_iter, counts, tails); !s) return s;
    return self->checkValidation();
  };
}

}  // namespace dpoint
