// libFuzzer target `gltf`: the glTF/GLB loader and scene walk `dpoint convert IN.glb` runs
// (converters/gltf_read.h: pre-checks, tinygltf, Draco, meshopt, sparse and quantized accessors,
// instancing), given the input's bytes as a file (InputFile::fromMemory; external URIs fail). Both
// of convert's paths run: readGltf (to PLY or GLB) and streamGltf (to CSV), and they must agree:
// the same points in the same order, or the same error. A third read asks for the base-colour
// textures (converters/gltf_texture.h: images decoded by stb_image, texture coordinates, transforms),
// as `convert --sample` does, and samples the surface with them.
#include <cstring>

#include "converters/gltf_read.h"
#include "fuzz/fuzz_support.h"
#include "ops/mesh_sample.h"

namespace {

class Collect final : public dpoint::GltfPointSink {
 public:
  dpoint::Status begin(const dpoint::GltfSummary& summary) override {
    summary_ = summary;
    return dpoint::okStatus();
  }
  dpoint::Status points(dpoint::PointSet& block) override {
    if (block.positions.empty() || block.positions.size() > dpoint::kGltfStreamBlockPoints)
      dpoint::fuzz::broken("stream blocks hold 1 to kGltfStreamBlockPoints points", std::to_string(block.size()));
    if (block.colors.size() != (summary_.colors ? block.positions.size() : 0))
      dpoint::fuzz::broken("a block has colours exactly when the summary says so", std::to_string(block.colors.size()));
    all_.positions.insert(all_.positions.end(), block.positions.begin(), block.positions.end());
    all_.colors.insert(all_.colors.end(), block.colors.begin(), block.colors.end());
    return dpoint::okStatus();
  }
  dpoint::GltfSummary summary_;
  dpoint::PointSet all_;
};

bool sameBits(const void* a, const void* b, size_t bytes) { return bytes == 0 || std::memcmp(a, b, bytes) == 0; }

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace dpoint;
  const InputFile input = InputFile::fromMemory("fuzz.glb", fuzz::bytesOf(data, size));
  GltfReadOptions options;
  // What a user bounds with --max-points; here it keeps each input's work small and bounded.
  options.max_points = 1 << 20;
  options.max_memory = fuzz::kMaxMemory;
  Result<PointSet> built = readGltf(input, options);
  fuzz::checkOutcome(built, input.path());

  // With textures: the same points, or an error (a texture's own, or a limit); what it gives fits
  // the set, and sampling with it stays on the texture's images.
  MeshTexture texture;
  GltfReadOptions textured_options = options;
  textured_options.texture = &texture;
  Result<PointSet> textured = readGltf(input, textured_options);
  fuzz::checkOutcome(textured, input.path());
  if (textured && built) {
    if (textured->positions != built->positions || textured->triangles != built->triangles)
      fuzz::broken("a read with textures gives the same points", std::to_string(textured->size()));
    if (texture.uv.size() != textured->size() || texture.triangle_image.size() != textured->triangles.size() / 3)
      fuzz::broken("texture coordinates per vertex and an image per triangle", std::to_string(texture.uv.size()));
    for (int32_t image : texture.triangle_image)
      if (image >= int32_t(texture.images.size())) fuzz::broken("a triangle's image exists", std::to_string(image));
    if (texture.textures() && textured->isMesh()) {
      SampleOptions sample;
      sample.count = 64;
      sample.texture = &texture;
      sample.max_memory = fuzz::kMaxMemory;
      Result<PointSet> points = sampleSurface(*textured, sample, input.path());
      if (points && points->colors.size() != points->size()) fuzz::broken("textured samples have colours", "");
    }
  }

  Collect sink;
  Status streamed = streamGltf(input, options, sink);
  if (!streamed) fuzz::checkError(streamed.error(), input.path());
  // point_io.h: the stream gives readGltf's points, colours and errors, in the same order. Only
  // the memory each needs differs, so a resource limit may stop one and not the other.
  const auto limited = [](const Error& e) { return e.code == ExitCode::kResourceLimit; };
  if ((!built && limited(built.error())) || (!streamed && limited(streamed.error()))) return 0;
  if (built && streamed) {
    const PointSet& a = *built;
    const PointSet& b = sink.all_;
    if (a.size() != b.size() || sink.summary_.points != a.size())
      fuzz::broken("stream and build give as many points", std::to_string(a.size()) + " vs " + std::to_string(b.size()));
    if (!sameBits(a.positions.data(), b.positions.data(), a.size() * sizeof(glm::dvec3)) ||
        a.colors.size() != b.colors.size() ||
        !sameBits(a.colors.data(), b.colors.data(), a.colors.size() * sizeof(glm::vec3)))
      fuzz::broken("stream and build give the same points", std::to_string(a.size()));
  } else if (built.ok() != streamed.ok()) {
    fuzz::broken("stream and build fail alike", built ? streamed.error().message : built.error().message);
  } else if (!built && built.error().message != streamed.error().message) {
    fuzz::broken("stream and build give the same error", built.error().message + " | " + streamed.error().message);
  }
  return 0;
}
