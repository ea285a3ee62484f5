// dpoint.render and dpoint.Renderer: a render as the CLI runs it (viewer/render_job.h), from a
// PointSet in memory or from files, with the picture as a NumPy array and the CLI's JSON report.
// The options are render's own, parsed by its parser (cli/cli_options.h).
#include <cmath>
#include <filesystem>
#include <memory>
#include <mutex>

#include <pybind11/stl/filesystem.h>

#include "cli/cli_options.h"
#include "image/image.h"
#include "python/module.h"
#include "viewer/modes.h"
#include "viewer/render_job.h"

namespace dpoint::python {
namespace {

// What a render gives back to Python.
struct RenderResultPy {
  Image image;
  std::string mode, backend, device;
  size_t points = 0;
  double predicted_bound_px = 0.0;
  bool bound_from_boxes = false;
  float point_size = 1.0f;
  std::optional<ErrorStats> error;
  std::vector<double> gpu_ms;
  std::vector<std::string> warnings;
  std::string report_json;  // renderReportJson: render --json's object (empty for a contact sheet)
};

// One Vulkan device kept across renders: a loop over views or modes makes it once. Its renders
// run one at a time, also when several Python threads share it (the GIL is released while they
// work): a Vulkan queue takes no two submissions at once, and the validation messages a render
// reports are the context's since that render began. The lock is taken with the GIL released, so a
// thread waiting for it holds up no other.
class Renderer {
 public:
  Renderer(const std::string& device, bool validate, uint64_t max_device_memory) {
    context_ = take(released([&] {
      Result<std::unique_ptr<VulkanContext>> made = VulkanContext::create(ContextOptions{device, validate, max_device_memory});
      if (!made) return Result<std::shared_ptr<VulkanContext>>(made.error());
      return Result<std::shared_ptr<VulkanContext>>(std::shared_ptr<VulkanContext>(std::move(*made)));
    }));
  }
  // Runs `work(context)` (with the GIL released) alone on the device; a closed Renderer's error else.
  template <typename Work>
  auto use(Work&& work) -> decltype(work(std::shared_ptr<VulkanContext>())) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!context_) return Error{"this Renderer is closed", ExitCode::kUsage};
    return work(context_);
  }
  std::string deviceName() {
    py::gil_scoped_release release;
    std::lock_guard<std::mutex> lock(mutex_);
    if (!context_) raise(Error{"this Renderer is closed", ExitCode::kUsage});
    return context_->facts.name;
  }
  void close() {
    std::shared_ptr<VulkanContext> closing;  // destroyed after the lock, with the GIL back
    py::gil_scoped_release release;
    std::lock_guard<std::mutex> lock(mutex_);
    closing = std::move(context_);
  }

 private:
  std::mutex mutex_;
  std::shared_ptr<VulkanContext> context_;  // null once closed
};

// What a RenderResult or _Renderer object holds (heldBy: TypeError for one made by __new__ alone).
const RenderResultPy& resultOf(const py::handle& self) { return heldBy<RenderResultPy>(self, "dpoint.render makes one"); }
Renderer& rendererOf(const py::handle& self) { return heldBy<Renderer>(self, "dpoint.Renderer() makes one"); }
// A read-only property's getter for one of RenderResult's fields.
template <auto Member>
auto field() {
  return [](const py::object& self) { return resultOf(self).*Member; };
}

RenderResultPy renderWith(const py::object& points_object, const std::vector<std::string>& inputs,
                          const std::vector<std::string>& args, const py::object& renderer_object, bool progress) {
  const std::shared_ptr<PointSet> points = heldSet(points_object);
  const std::shared_ptr<Renderer> held_renderer = heldObject<Renderer>(renderer_object, "dpoint.Renderer() makes one");
  Renderer* renderer = held_renderer.get();
  if (!points && inputs.empty()) raise(Error{"render: no points and no input files", ExitCode::kUsage});
  RenderRequest request = take(renderRequestOf(args));
  if (points) {
    request.points = points;
  } else {
    request.inputs = inputs;
  }
  const SetInUse in_use(points.get());
  RenderOutcome outcome = take(released([&]() -> Result<RenderOutcome> {
    Progress bar(progressFile(progress), "render");
    Result<RenderOutcome> done = !renderer ? runRenderJob(request, bar)
                                           : renderer->use([&](const std::shared_ptr<VulkanContext>& context) {
                                               request.context = context;
                                               return runRenderJob(request, bar);
                                             });
    // The set as read is given back on its own thread (RenderOutcome::read_set): waited for here,
    // without the GIL, so other Python threads run meanwhile.
    if (done) done->read_set.wait();
    return done;
  }));
  // As the CLI: with the validation layer on, any message fails the run.
  if (!outcome.validation_messages.empty()) {
    std::string text = std::to_string(outcome.validation_messages.size()) + " Vulkan validation message(s):";
    for (const std::string& m : outcome.validation_messages) text += "\n" + m;
    raise(Error{text, ExitCode::kNoDevice});
  }
  RenderResultPy r;
  if (request.views == 1) r.report_json = renderReportJson(request, outcome);
  r.image = std::move(outcome.image);
  r.mode = std::string(modeName(outcome.prediction.mode));
  r.backend = backendName(outcome.backend);
  r.device = outcome.device.name;
  r.points = outcome.points;
  r.predicted_bound_px = outcome.prediction.bound_px;
  // From boxes, not every point: a streamed set's batch boxes, or the box --mode auto took its
  // choice's bound from (report["predicted_from"] says which).
  r.bound_from_boxes = outcome.prediction.from_boxes || (outcome.prediction.choice && outcome.prediction.choice->from_box);
  r.point_size = outcome.point_size;
  if (outcome.error && anyMeasured(outcome.error->stats)) r.error = outcome.error->stats;
  r.gpu_ms = outcome.result.gpu_ms;
  r.warnings = outcome.warnings;
  return r;
}

}  // namespace

void addRender(py::module_& m) {
  py::class_<RenderResultPy, std::shared_ptr<RenderResultPy>>(m, "RenderResult", R"(What a render gives back.

image: (H, W, 4) uint8 RGBA (a view, no copy); mode, backend, device: what ran; predicted_bound_px:
the mode's error bound for the view (inf: unbounded); error_px: dict of max, p99, rms and more
(render(..., error=True)), else None; gpu_ms: each timed frame; report: render --json's object;
warnings: what makes the picture wrong or poor. save(path) writes the PNG the CLI writes; in
Jupyter the result shows as its picture.)")
      .def_property_readonly("image",
                             [](const py::object& self) {
                               const RenderResultPy& r = resultOf(self);
                               const auto h = static_cast<py::ssize_t>(r.image.height);
                               const auto w = static_cast<py::ssize_t>(r.image.width);
                               return py::array_t<uint8_t>({h, w, py::ssize_t{4}}, {w * 4, py::ssize_t{4}, py::ssize_t{1}},
                                                           r.image.rgba.data(), self);
                             })
      .def_property_readonly("mode", field<&RenderResultPy::mode>())
      .def_property_readonly("backend", field<&RenderResultPy::backend>())
      .def_property_readonly("device", field<&RenderResultPy::device>())
      .def_property_readonly("points", field<&RenderResultPy::points>())
      .def_property_readonly("predicted_bound_px", field<&RenderResultPy::predicted_bound_px>())
      .def_property_readonly("bound_from_boxes", field<&RenderResultPy::bound_from_boxes>())
      .def_property_readonly("point_size", field<&RenderResultPy::point_size>())
      .def_property_readonly("gpu_ms", field<&RenderResultPy::gpu_ms>())
      .def_property_readonly("_warnings", field<&RenderResultPy::warnings>())
      .def_property_readonly("error_px",
                             [](const py::object& self) -> py::object {
                               const RenderResultPy& r = resultOf(self);
                               if (!r.error) return py::none();
                               py::dict d;
                               d["max"] = r.error->max_px, d["p99"] = r.error->p99_px, d["rms"] = r.error->rms_px;
                               d["share_off_half_px"] = r.error->share_off_half_px;
                               d["points"] = r.error->points, d["lost"] = r.error->lost;
                               return d;
                             })
      .def_property_readonly("_report_json", field<&RenderResultPy::report_json>())
      .def("png", [](const py::object& self) {
             std::vector<unsigned char> bytes = take(pngBytes(resultOf(self).image, "the picture"));
             return py::bytes(reinterpret_cast<const char*>(bytes.data()), bytes.size());
           }, "The picture as the bytes of the PNG file the CLI writes")
      .def("save", [](const py::object& self, const std::filesystem::path& file) {  // a str or os.PathLike
             const RenderResultPy& r = resultOf(self);
             const std::string path = file.string();
             Status ok = checkPictureOutput(path);
             // The CLI's message names its flag: here the argument is save's.
             if (!ok && ok.error().message.rfind("-o ", 0) == 0) ok = Error{"save: " + ok.error().message.substr(3), ok.error().code};
             check(ok);
             check(writePng(path, r.image));
           }, py::arg("path"), "Writes the picture as PNG, whole or not at all");

  py::class_<Renderer, std::shared_ptr<Renderer>>(m, "_Renderer")
      .def(py::init<const std::string&, bool, uint64_t>(), py::arg("device"), py::arg("validate"),
           py::arg("max_device_memory"))
      .def_property_readonly("device", [](const py::object& self) { return rendererOf(self).deviceName(); })
      .def("close", [](const py::object& self) { rendererOf(self).close(); });

  m.def("_render", &renderWith, py::arg("points"), py::arg("inputs"), py::arg("args"), py::arg("renderer"),
        py::arg("progress"));
}

}  // namespace dpoint::python
