// dpoint.generate, dpoint.info and dpoint.bench: the CLI's commands run in this process
// (cli/cli_run.h's runEmbedded: the same parser, checks and messages), generate handing its set
// back rather than writing it; info's report from the library (viewer/info_report.h).
#include <cstdlib>

#include "cli/cli_options.h"
#include "cli/cli_run.h"
#include "core/memory.h"
#include "python/module.h"
#include "viewer/info_report.h"

namespace dpoint::python {
namespace {

// The run's error (any non-zero code has one), raised in Python.
void raiseFailed(const EmbeddedRun& run) {
  if (run.code == 0) return;
  raise(run.error ? *run.error : Error{"dpoint exited with code " + std::to_string(run.code), ExitCode::kBadInput});
}

std::vector<std::string> command(std::vector<std::string> head, const std::vector<std::string>& args, bool progress) {
  head.insert(head.end(), args.begin(), args.end());
  if (!progress) head.emplace_back("--quiet");
  return head;
}

}  // namespace

void addCommands(py::module_& m) {
  m.def(
      "_generate",
      [](const std::string& kind, const std::vector<std::string>& args, bool progress) -> py::object {
        const std::vector<std::string> line = command({"generate", kind}, args, progress);
        EmbeddedRun run = released([&] { return runEmbedded(line, true); });
        raiseFailed(run);
        if (!run.points) return py::none();  // --help
        return py::cast(std::make_shared<PointSet>(std::move(*run.points)));
      },
      py::arg("kind"), py::arg("args"), py::arg("progress"));

  m.def(
      "_info",
      [](const py::object& points_object, const std::vector<std::string>& inputs,
         const std::vector<std::string>& camera_args, size_t sample, unsigned threads, bool allow_nonfinite,
         const std::string& stream, uint64_t max_memory, const std::vector<std::string>& columns, bool progress) {
        const std::shared_ptr<PointSet> points = heldSet(points_object);
        const CameraRequest camera = take(cameraRequestOf(camera_args));
        if (stream != "auto" && stream != "on" && stream != "off")
          raise(Error{"--stream " + stream + ": must be auto, on or off", ExitCode::kUsage});  // as the CLI's oneOf
        if (sample < 1 || sample > 100000000)
          raise(Error{"sample " + std::to_string(sample) + ": must be a number from 1 to 100000000", ExitCode::kUsage});
        InfoOptions options{camera.spec, sample, camera.tolerance_px, threads, std::nullopt};
        const SetInUse in_use(points.get());
        InfoReport report = take(released([&] {
          if (points) return describePoints(*points, "points", options);
          Progress bar(progressFile(progress), "info");
          InfoInputs files{inputs, stream, allow_nonfinite, max_memory};
          files.columns = columns;
          return describeFiles(files, options, bar);
        }));
        warnAtCaller(report.notices);  // what the readers read past, as read warns it (the CLI's notes)
        return infoReportJson(report);
      },
      py::arg("points"), py::arg("inputs"), py::arg("camera_args"), py::arg("sample"), py::arg("threads"),
      py::arg("allow_nonfinite"), py::arg("stream"), py::arg("max_memory"), py::arg("columns"), py::arg("progress"));

  m.def(
      "_bench",
      [](const std::vector<std::string>& args, bool progress) {
        const std::vector<std::string> line = command({"bench"}, args, progress);
        EmbeddedRun run = released([&] { return runEmbedded(line, false); });
        raiseFailed(run);
      },
      py::arg("args"), py::arg("progress"));
}

}  // namespace dpoint::python
