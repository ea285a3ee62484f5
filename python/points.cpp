// dpoint.PointSet, dpoint.read and dpoint.write: the data model with NumPy arrays in and out.
//
// A PointSet owns the library's PointSet (double positions, float colours, uint32 triangles). Its
// arrays are views of that memory, without a copy: positions (N, 3) float64, colors (N, 3) float32
// (linear 0..1) and triangles (M, 3) uint32, each keeping the PointSet alive. Made from NumPy
// arrays it copies them once into its own memory (the library's vectors cannot adopt NumPy's), so
// a set made from an (N, 3) array holds the array and the copy until the caller drops the array.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <unordered_map>

#include "converters/gltf_read.h"
#include "converters/las_crs.h"
#include "converters/point_io.h"
#include "ops/mesh_sample.h"
#include "core/memory.h"
#include "core/text.h"
#include "ops/point_order.h"
#include "python/module.h"

namespace dpoint::python {
namespace {

static_assert(sizeof(glm::dvec3) == 3 * sizeof(double) && sizeof(glm::vec3) == 3 * sizeof(float),
              "PointSet's vectors are seen as (N, 3) arrays");

std::string shapeText(const py::array& a) {
  std::string text = "(";
  for (py::ssize_t d = 0; d < a.ndim(); ++d) text += (d ? ", " : "") + std::to_string(a.shape(d));
  return text + (a.ndim() == 1 ? ",)" : ")");
}

std::string dtypeText(const py::array& a) { return py::str(a.dtype()).cast<std::string>(); }

// `value` as an array of `columns` columns (or, with two_d, two) of a real number type, else a
// TypeError (not numbers) or ValueError (the shape).
py::array asTable(const py::handle& value, const char* name, bool two_d) {
  py::array a = py::array::ensure(value);
  if (!a) throw py::type_error(std::string(name) + ": expected an array of numbers, got " +
                               py::str(py::type::of(value)).cast<std::string>());
  const char kind = a.dtype().kind();
  if (kind != 'f' && kind != 'i' && kind != 'u' && kind != 'b')
    throw py::type_error(std::string(name) + ": expected real numbers, got dtype " + dtypeText(a));
  if (a.ndim() != 2 || (a.shape(1) != 3 && !(two_d && a.shape(1) == 2)))
    throw py::value_error(std::string(name) + ": expected shape (N, 3)" + (two_d ? " or (N, 2)" : "") + ", got " +
                          shapeText(a));
  return a;
}

const char* kAxisNames[] = {"x", "y", "z"};

void setPositions(PointSet& set, const py::handle& value, bool allow_nonfinite) {
  py::array table = asTable(value, "positions", true);
  // float64 in any strides is read in place; another type is converted once.
  auto doubles = py::array_t<double>::ensure(table);
  if (!doubles) throw py::type_error("positions: cannot be read as float64 (dtype " + dtypeText(table) + ")");
  const auto view = doubles.unchecked<2>();
  const size_t n = static_cast<size_t>(view.shape(0));
  const bool planar = view.shape(1) == 2;
  set.positions.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const auto row = static_cast<py::ssize_t>(i);
    glm::dvec3 p(view(row, 0), view(row, 1), planar ? 0.0 : view(row, 2));
    if (!allow_nonfinite)
      for (int axis = 0; axis < 3; ++axis)
        if (!std::isfinite(p[axis]))
          raise(Error{"positions: row " + std::to_string(i) + ", " + kAxisNames[axis] + ": " +
                          (std::isnan(p[axis]) ? "nan" : p[axis] > 0 ? "inf" : "-inf") +
                          " is not a finite coordinate (allow_nonfinite=True keeps it)",
                      ExitCode::kBadInput});
    set.positions[i] = p;
  }
  // (N, 2) is a 2D set; (N, 3) has z, even where every z is 0 (a flat scan), as a 3-column CSV has.
  set.z_axis = planar ? ZAxis::kAbsent : ZAxis::kPresent;
}

// The NumPy views of each set alive now (their bases: viewBase), by set. The GIL guards it: views
// are made and freed with it held.
std::unordered_map<const PointSet*, size_t>& liveViews() {
  static std::unordered_map<const PointSet*, size_t> views;
  return views;
}

// A view's base: it holds the set's Python object, and counts among the set's live views while it
// lives, so that storage no view can see is freed at once (retireKeepingViews).
py::object viewBase(const py::object& self) {
  const PointSet* set = &setOf(self);
  ++liveViews()[set];
  auto* held = new std::pair<const PointSet*, py::object>(set, self);
  return py::capsule(held, [](void* p) {
    auto* pair = static_cast<std::pair<const PointSet*, py::object>*>(p);
    if (--liveViews()[pair->first] == 0) liveViews().erase(pair->first);
    delete pair;  // drops the set's reference (with the GIL, as every deallocation)
  });
}

// Keeps `kept` alive as long as `owner` (a pybind11 instance, which takes weak references): the
// patient of pybind11's own keep_alive, without an argument to hang it on.
void keepWhileAlive(const py::handle& owner, py::object kept) {
  py::handle patient = kept.release();  // one reference, dropped when the owner goes
  py::cpp_function drop([patient](py::handle weakref) {
    patient.dec_ref();
    weakref.dec_ref();
  });
  py::weakref(owner, drop).release();
}

// Sets a vector that NumPy views may see. A view holds the set, not the vector's storage, so that
// storage must never be freed while the set lives: a value that fits is copied into it (resize
// within the capacity does not reallocate, and clear() keeps it), and a larger one gets new storage
// while the old is handed to the set's Python object to keep. A view made before then still reads
// memory of its own, never freed memory.
// Hands `target`'s storage to the set's Python object to keep (views of it stay valid) and leaves
// `target` empty.
template <typename Vector>
void retireKeepingViews(const py::handle& self, Vector& target) {
  if (target.capacity() == 0) return;
  // No view alive: nothing can see the storage, which is freed now (a review finding: removing and
  // adding an attribute 200 times kept 1.5 GB until the set went).
  if (!liveViews().count(&setOf(self))) {
    target = Vector();
    return;
  }
  auto* retired = new Vector(std::move(target));  // a move keeps the storage where it is
  keepWhileAlive(self, py::capsule(retired, [](void* p) { delete static_cast<Vector*>(p); }));
  target = Vector();
}

template <typename Vector>
void replaceKeepingViews(const py::handle& self, Vector& target, Vector values) {
  if (values.size() <= target.capacity()) {
    target.resize(values.size());
    std::copy(values.begin(), values.end(), target.begin());
    return;
  }
  retireKeepingViews(self, target);
  target = std::move(values);
}

// uint8 (0..255, as a PLY's uchar colours are read: k / 255) or floats (linear 0..1). `self`: the
// set's Python object when it exists (its views are kept valid), else none (a set being made).
void setColors(PointSet& set, const py::handle& value, const py::handle& self = py::handle()) {
  if (value.is_none()) {
    set.colors.clear();
    set.color_full_scale = 0;
    set.colors_read_as_fractions = false;
    return;
  }
  py::array table = asTable(value, "colors", false);
  if (static_cast<size_t>(table.shape(0)) != set.size())
    throw py::value_error("colors: " + std::to_string(table.shape(0)) + " rows for " + std::to_string(set.size()) +
                          " points");
  const char kind = table.dtype().kind();
  const size_t n = set.size();
  ColorArray colors(n);  // every element written below
  if (kind == 'u' && table.itemsize() == 1) {
    float byte_color[256];  // k / 255.0f, as the PLY reader rounds it
    for (int k = 0; k < 256; ++k) byte_color[k] = static_cast<float>(k) / 255.0f;
    const py::array_t<uint8_t> bytes = py::array_t<uint8_t>::ensure(table);  // named: the view points into it
    const auto view = bytes.unchecked<2>();
    for (size_t i = 0; i < n; ++i)
      for (py::ssize_t c = 0; c < 3; ++c) colors[i][static_cast<int>(c)] = byte_color[view(static_cast<py::ssize_t>(i), c)];
  } else if (kind == 'f') {
    // Named: a converted array (float64, float16, big-endian) is a new one the view points into;
    // as a temporary it was freed at once and read after (a review finding: a segfault, or
    // garbage colours, for 100,000 float64 colours).
    const py::array_t<float> floats = py::array_t<float>::ensure(table);
    const auto view = floats.unchecked<2>();
    for (size_t i = 0; i < n; ++i)
      for (py::ssize_t c = 0; c < 3; ++c) {
        const float v = view(static_cast<py::ssize_t>(i), c);
        if (!(v >= 0.0f && v <= 1.0f))
          raise(Error{"colors: row " + std::to_string(i) + ", column " + std::to_string(c) + ": " + std::to_string(v) +
                          " is outside 0..1 (float colours are linear 0..1; uint8 ones 0..255)",
                      ExitCode::kBadInput});
        colors[i][static_cast<int>(c)] = v;
      }
  } else {
    throw py::type_error("colors: expected uint8 (0..255) or floats (0..1), got dtype " + dtypeText(table));
  }
  if (self)
    replaceKeepingViews(self, set.colors, std::move(colors));
  else
    set.colors = std::move(colors);
  // New colours have no source form: a set read from a file of 0..255 integers wrote colours set
  // after as 8-bit integers (a review finding: 0.123456 written as 31). Nor were they read from a
  // file: a writer of integers rounds them as it rounds generated ones.
  set.color_full_scale = 0;
  set.colors_read_as_fractions = false;
}

// The dimension type of a NumPy dtype: its integer and float types, bool as uint8.
DimType dimTypeOf(const py::array& array, const std::string& name) {
  const char kind = array.dtype().kind();
  const size_t size = static_cast<size_t>(array.itemsize());
  if (kind == 'b') return DimType::kU8;
  for (size_t t = 0; t < kDimTypeCount; ++t) {
    const DimType type = static_cast<DimType>(t);
    if (dimTypeSize(type) == size && (kind == 'f') == dimTypeIsFloat(type) &&
        (kind == 'f' || (kind == 'i') == dimTypeIsSigned(type)) && (kind == 'f' || kind == 'i' || kind == 'u'))
      return type;
  }
  throw py::type_error("attribute '" + name + "': dtype " + dtypeText(array) +
                       " is not an integer, float or bool type");
}

// PointSet.viewpoint as Python has it (the property, the pickle): None, or a tuple of 7 numbers.
py::object viewpointObject(const std::optional<std::array<double, 7>>& pose) {
  return pose ? py::object(py::tuple(py::cast(*pose))) : py::object(py::none());
}

// And back: None, or 7 finite numbers (ValueError else; `what` names it in the message).
std::optional<std::array<double, 7>> viewpointOf(const std::optional<std::vector<double>>& pose, const std::string& what) {
  if (!pose) return std::nullopt;
  if (pose->size() != 7 || !std::all_of(pose->begin(), pose->end(), [](double v) { return std::isfinite(v); }))
    throw py::value_error(what + ": 7 finite numbers (tx, ty, tz, qw, qx, qy, qz), or None");
  std::array<double, 7> out{};
  std::copy(pose->begin(), pose->end(), out.begin());
  return out;
}

// A pickle's state of a set: a version, then every array as bytes and every fact (pointSetFromState).
py::tuple pointSetState(const PointSet& s) {
  const auto bytes = [](const void* data, size_t size) { return py::bytes(static_cast<const char*>(data), size); };
  py::list dims;
  for (const Dimension& d : s.dimensions.all())
    dims.append(py::make_tuple(d.name, static_cast<int>(d.type), bytes(d.bytes.data(), d.bytes.size())));
  py::object las = py::none();
  if (s.las) {
    const LasSource& l = *s.las;
    py::list vlrs, extra;
    for (const LasVlr& v : l.vlrs) vlrs.append(py::make_tuple(v.user_id, v.record_id, v.description, py::bytes(v.data), v.extended));
    for (const auto& [name, descriptor] : l.extra_bytes) extra.append(py::make_tuple(name, py::bytes(descriptor)));
    las = py::make_tuple(l.version_minor, l.point_format, py::make_tuple(l.scale.x, l.scale.y, l.scale.z),
                         py::make_tuple(l.offset.x, l.offset.y, l.offset.z), l.global_encoding, l.file_source_id, vlrs, extra);
  }
  return py::make_tuple(1, bytes(s.positions.data(), s.positions.size() * sizeof(glm::dvec3)),
                        bytes(s.colors.data(), s.colors.size() * sizeof(glm::vec3)),
                        bytes(s.triangles.data(), s.triangles.size() * sizeof(uint32_t)), dims,
                        s.color_full_scale, static_cast<int>(s.z_axis), s.z_up, las,
                        viewpointObject(s.viewpoint), s.colors_read_as_fractions, py::bytes(s.crs));
}

std::shared_ptr<PointSet> pointSetFromState(const py::tuple& t) {
  // 10 items since the viewpoint, 11 since colors_read_as_fractions, 12 since the CRS; a pickle of
  // 9 to 11 (made before) loads without them.
  if (t.size() < 9 || t.size() > 12 || t[0].cast<int>() != 1)
    throw py::value_error("PointSet: not a pickle of this version's PointSet");
  auto s = std::make_shared<PointSet>();
  const auto fill = [](const py::handle& from, auto& to) {
    const std::string b = from.cast<std::string>();
    using T = typename std::decay_t<decltype(to)>::value_type;
    if (b.size() % sizeof(T) != 0) throw py::value_error("PointSet: a pickled array is not whole values");
    to.resize(b.size() / sizeof(T));
    if (!b.empty()) std::memcpy(to.data(), b.data(), b.size());
  };
  fill(t[1], s->positions);
  fill(t[2], s->colors);
  fill(t[3], s->triangles);
  for (const py::handle& d : t[4].cast<py::list>()) {
    const py::tuple dim = d.cast<py::tuple>();
    const int type = dim[1].cast<int>();
    if (type < 0 || type >= static_cast<int>(kDimTypeCount)) throw py::value_error("PointSet: a pickled attribute's type");
    Dimension& column = s->dimensions.append(dim[0].cast<std::string>(), static_cast<DimType>(type), 0);
    const std::string b = dim[2].cast<std::string>();
    if (b.size() != s->positions.size() * dimTypeSize(column.type)) throw py::value_error("PointSet: a pickled attribute's length");
    column.bytes.assign(b.begin(), b.end());
  }
  if (s->colors.size() != 0 && s->colors.size() != s->positions.size())
    throw py::value_error("PointSet: pickled colours for another count of points");
  if (s->triangles.size() % 3 != 0 || s->firstBadTriangleIndex() != s->triangles.size())
    throw py::value_error("PointSet: pickled triangles that name no point");
  s->color_full_scale = t[5].cast<uint16_t>();
  s->z_axis = static_cast<ZAxis>(t[6].cast<int>());
  s->z_up = t[7].cast<bool>();
  if (t.size() >= 10) s->viewpoint = viewpointOf(t[9].cast<std::optional<std::vector<double>>>(), "PointSet: a pickled viewpoint");
  if (t.size() >= 11) s->colors_read_as_fractions = t[10].cast<bool>() && !s->colors.empty();
  if (t.size() >= 12) s->crs = t[11].cast<std::string>();
  if (!t[8].is_none()) {
    const py::tuple l = t[8].cast<py::tuple>();
    LasSource las;
    las.version_minor = l[0].cast<int>(), las.point_format = l[1].cast<int>();
    const py::tuple scale = l[2].cast<py::tuple>(), offset = l[3].cast<py::tuple>();
    for (int k = 0; k < 3; ++k) las.scale[k] = scale[k].cast<double>(), las.offset[k] = offset[k].cast<double>();
    las.global_encoding = l[4].cast<uint16_t>(), las.file_source_id = l[5].cast<uint16_t>();
    for (const py::handle& v : l[6].cast<py::list>()) {
      const py::tuple r = v.cast<py::tuple>();
      las.vlrs.push_back({r[0].cast<std::string>(), r[1].cast<uint16_t>(), r[2].cast<std::string>(), r[3].cast<std::string>(),
                          r[4].cast<bool>()});
    }
    for (const py::handle& e : l[7].cast<py::list>()) {
      const py::tuple r = e.cast<py::tuple>();
      las.extra_bytes.push_back({r[0].cast<std::string>(), r[1].cast<std::string>()});
    }
    s->las = std::move(las);
  }
  return s;
}

// Sets (adds or replaces) a dimension from a 1-D array of one value per point, in the array's own
// dtype. Views of a replaced column keep memory of their own (replaceKeepingViews).
void setAttribute(const py::handle& self, PointSet& set, const std::string& name, const py::handle& value) {
  if (name.empty()) throw py::value_error("attribute: the name is empty");
  for (const char* taken : {"x", "y", "z", "r", "g", "b"})
    if (name == taken) throw py::value_error("attribute '" + name + "': a coordinate or colour, not an attribute");
  py::array array = py::array::ensure(value);
  if (!array) throw py::type_error("attribute '" + name + "': not an array");
  if (array.ndim() != 1 || static_cast<size_t>(array.shape(0)) != set.size())
    throw py::value_error("attribute '" + name + "': expected " + std::to_string(set.size()) +
                          " values (one per point) in one dimension");
  const DimType type = dimTypeOf(array, name);
  // Values in the host's byte order: a big-endian column (FITS, HDF5) was copied as its bytes.
  if (!array.dtype().attr("isnative").cast<bool>())
    array = py::array::ensure(array.attr("astype")(array.dtype().attr("newbyteorder")("=")));
  py::array contiguous = py::array::ensure(array, py::array::c_style | py::array::forcecast);
  DimensionBytes bytes(set.size() * dimTypeSize(type));  // unset, then every byte copied
  if (!bytes.empty()) std::memcpy(bytes.data(), contiguous.data(), bytes.size());
  Dimension* d = set.dimensions.find(name);
  if (!d) {
    set.dimensions.append(name, type, 0).bytes = std::move(bytes);
    return;
  }
  if (d->type != type) {
    retireKeepingViews(self, d->bytes);
    d->type = type;
    d->bytes = std::move(bytes);
    return;
  }
  replaceKeepingViews(self, d->bytes, std::move(bytes));
}

void setTriangles(PointSet& set, const py::handle& value, const py::handle& self = py::handle()) {
  if (value.is_none()) {
    set.triangles.clear();
    return;
  }
  py::array table = asTable(value, "triangles", false);
  const char kind = table.dtype().kind();
  if (kind != 'i' && kind != 'u') throw py::type_error("triangles: expected integers, got dtype " + dtypeText(table));
  // Read as int64, or uint64 for unsigned input (uint64 above 2^63 would wrap to a negative index).
  auto fill = [&](auto view) {
    std::vector<uint32_t> triangles(static_cast<size_t>(view.shape(0)) * 3);
    for (py::ssize_t t = 0; t < view.shape(0); ++t)
      for (py::ssize_t c = 0; c < 3; ++c) {
        const auto v = view(t, c);
        if (v < 0 || static_cast<uint64_t>(v) >= set.size())
          raise(Error{"triangles: row " + std::to_string(t) + ": vertex " + std::to_string(v) + " is not one of the " +
                          std::to_string(set.size()) + " points",
                      ExitCode::kBadInput});
        triangles[static_cast<size_t>(t * 3 + c)] = static_cast<uint32_t>(v);
      }
    return triangles;
  };
  std::vector<uint32_t> triangles = kind == 'u' ? fill(py::array_t<uint64_t>::ensure(table).unchecked<2>())
                                                : fill(py::array_t<int64_t>::ensure(table).unchecked<2>());
  if (self)
    replaceKeepingViews(self, set.triangles, std::move(triangles));
  else
    set.triangles = std::move(triangles);
}

// A view of `rows` × 3 values at `data`, kept alive by `owner`.
template <typename T>
py::array view3(const py::object& owner, const T* data, size_t rows) {
  const auto n = static_cast<py::ssize_t>(rows);
  if (rows == 0) return py::array_t<T>({n, py::ssize_t{3}});
  return py::array_t<T>({n, py::ssize_t{3}}, {py::ssize_t{3 * sizeof(T)}, py::ssize_t{sizeof(T)}}, data, viewBase(owner));
}

// max_memory and the like: None or 0 (the default), bytes as a number, or a size as text ("8G").
Result<uint64_t> memoryOption(const std::string& name, const py::object& given) {
  if (given.is_none()) return uint64_t{0};
  const bool boolean = py::isinstance<py::bool_>(given) ||
                       (py::hasattr(given, "dtype") && py::str(given.attr("dtype").attr("kind")).cast<std::string>() == "b");
  // A NumPy integer (numpy.int64(10**9)) as the Python int it stands for.
  py::object value = given;
  if (!boolean && !py::isinstance<py::int_>(given) && PyIndex_Check(given.ptr()))
    value = py::reinterpret_steal<py::object>(PyNumber_Index(given.ptr()));
  if (!value) throw py::error_already_set();
  if (boolean ||
      !(py::isinstance<py::int_>(value) || py::isinstance<py::float_>(value) || py::isinstance<py::str>(value)))
    throw py::type_error(name + ": expected bytes (a number) or a size such as \"8G\", got " +
                         py::str(py::type::of(value)).cast<std::string>());
  if (py::isinstance<py::int_>(value)) {
    if (value.equal(py::int_(0))) return uint64_t{0};
    if (value < py::int_(0) || value > py::int_(std::numeric_limits<uint64_t>::max()))
      return Error{name + " " + py::str(value).cast<std::string>() + ": not a size in bytes", ExitCode::kUsage};
    return value.cast<uint64_t>();
  }
  return parseMemorySize(name, py::str(value).cast<std::string>());
}

std::optional<LasColorSource> lasColorSource(const std::string& name) {
  if (name == "auto") return LasColorSource::kAuto;
  if (name == "rgb") return LasColorSource::kRgb;
  if (name == "intensity") return LasColorSource::kIntensity;
  if (name == "classification") return LasColorSource::kClassification;
  if (name == "none") return LasColorSource::kNone;
  return std::nullopt;
}

std::shared_ptr<PointSet> readFile(const std::string& path, unsigned threads, bool allow_nonfinite,
                                   const std::string& colors, const py::object& max_memory, int scene, bool all_scenes,
                                   uint64_t max_points, const std::optional<std::vector<std::string>>& columns,
                                   bool progress) {
  const std::optional<LasColorSource> source = lasColorSource(colors);
  if (!source)
    raise(Error{"colors: '" + colors + "' is not one of auto, rgb, intensity, classification, none", ExitCode::kUsage});
  const uint64_t limit = take(memoryOption("max_memory", max_memory));
  GltfReadOptions g;
  if (scene < -1) raise(Error{"scene " + std::to_string(scene) + ": must be 0 or more", ExitCode::kUsage});  // as --scene
  g.scene = scene, g.all_scenes = all_scenes, g.max_points = max_points;
  std::vector<std::string> notices;  // what the reader read past: Python's warnings, as the CLI's notes
  auto set = std::make_shared<PointSet>(take(released([&] {
    Progress bar(progressFile(progress), "read");
    ReadOptions r{threads, allow_nonfinite, &bar};
    r.max_memory = limit;
    r.las_color = *source;
    r.notices = &notices;
    if (columns) r.columns = *columns;
    return readInput(path, r, g, InputOptionNames{"scene and all_scenes", "max_points"});
  })));
  warnAtCaller(notices);
  return set;
}

// The samples of `mesh`, or of the file at `path` (read as convert --sample reads it, textures
// included: their notes go to Python's warnings).
std::shared_ptr<PointSet> sampleMesh(const PointSet* mesh, const std::string& path, uint64_t count,
                                     const std::string& method, uint64_t seed, unsigned threads,
                                     const py::object& max_memory, bool progress) {
  SampleOptions options;
  options.count = count;
  options.method = take(parseSampleMethod(method));
  options.seed = seed;
  options.threads = threads;
  options.max_memory = take(memoryOption("max_memory", max_memory));
  MeshTexture texture;
  std::optional<PointSet> read;
  const SetInUse in_use(mesh);
  auto sampled = std::make_shared<PointSet>(take(released([&]() -> Result<PointSet> {
    Progress bar(progressFile(progress), "sample");
    options.progress = &bar;
    if (!mesh) {
      ReadOptions r{threads, false, &bar};
      r.max_memory = options.max_memory;
      r.texture = &texture;
      Result<PointSet> file = readInput(path, r, GltfReadOptions{});
      if (!file) return file.error();
      read = std::move(*file);
      mesh = &*read;
      options.texture = &texture;
    }
    return sampleSurface(*mesh, options, path.empty() ? std::string("the mesh") : path);
  })));
  warnAtCaller(texture.notes);
  return sampled;
}

}  // namespace

void addPointSet(py::module_& m) {
  py::class_<PointSet, std::shared_ptr<PointSet>>(m, "PointSet", R"(Points with double-precision positions.

PointSet(positions, colors=None, triangles=None, *, allow_nonfinite=False)

positions: (N, 3) or (N, 2) array of real numbers (float64 kept exactly; (N, 2) means z = 0, a 2D
set). colors: None, (N, 3) uint8 (0..255) or floats (linear 0..1). triangles: None or (M, 3)
integer vertex indices. The arrays are copied once into the set; its attributes are views of
that memory, without copying (writing into them changes the set).)")
      .def(py::init([](const py::object& positions, const py::object& colors, const py::object& triangles,
                       bool allow_nonfinite) {
             auto set = std::make_shared<PointSet>();
             setPositions(*set, positions, allow_nonfinite);
             setColors(*set, colors);
             setTriangles(*set, triangles);
             return set;
           }),
           py::arg("positions"), py::arg("colors") = py::none(), py::arg("triangles") = py::none(), py::kw_only(),
           py::arg("allow_nonfinite") = false)
      .def("__len__", [](const py::object& self) { return setOf(self).size(); })
      .def_property_readonly(
          "positions",
          [](const py::object& self) {
            const PointSet& s = setOf(self);
            return view3(self, reinterpret_cast<const double*>(s.positions.data()), s.size());
          },
          "(N, 3) float64 view of the positions (no copy)")
      .def_property(
          "colors",
          [](const py::object& self) -> py::object {
            const PointSet& s = setOf(self);
            if (!s.hasColors()) return py::none();
            return view3(self, reinterpret_cast<const float*>(s.colors.data()), s.size());
          },
          [](const py::object& self, const py::object& colors) {
            PointSet& s = setOf(self);
            checkNotInUse(s, "colors");
            setColors(s, colors, self);
          },
          "(N, 3) float32 view of the linear 0..1 colours (no copy), or None. Set from uint8 or floats, or None")
      .def_property(
          "triangles",
          [](const py::object& self) -> py::object {
            const PointSet& s = setOf(self);
            if (!s.isMesh()) return py::none();
            return view3(self, s.triangles.data(), s.triangles.size() / 3);
          },
          [](const py::object& self, const py::object& triangles) {
            PointSet& s = setOf(self);
            checkNotInUse(s, "triangles");
            setTriangles(s, triangles, self);
          },
          "(M, 3) uint32 view of the triangles' vertex indices (no copy), or None")
      .def_property_readonly(
          "attributes",
          [](const py::object& self) {
            // One NumPy view per dimension (core/dimensions.h), in its own dtype, no copy.
            const PointSet& s = setOf(self);
            py::dict out;
            for (const Dimension& d : s.dimensions.all()) {
              const py::dtype dtype(dimTypeName(d.type));
              const std::vector<py::ssize_t> shape = {static_cast<py::ssize_t>(d.size())};
              const std::vector<py::ssize_t> strides = {static_cast<py::ssize_t>(dimTypeSize(d.type))};
              out[py::str(d.name)] = d.size() == 0 ? py::array(dtype, shape, strides)
                                                   : py::array(dtype, shape, strides, d.bytes.data(), viewBase(self));
            }
            return out;
          },
          "The per-point attributes (intensity, classification, GPS time, a LAS file's extra bytes, a PLY's\n"
          "other properties): a dict of name to a 1-D NumPy view in the attribute's own dtype (no copy)")
      .def(
          "set_attribute",
          [](const py::object& self, const std::string& name, const py::object& values) {
            PointSet& s = setOf(self);
            checkNotInUse(s, "set_attribute");
            setAttribute(self, s, name, values);
          },
          py::arg("name"), py::arg("values"),
          "Adds or replaces attribute `name` from a 1-D array of one value per point, kept in its dtype\n"
          "(integers, float32/64; bool as uint8). Writers write it as a LAS field (a known name such as\n"
          "intensity or classification) or extra bytes, a PLY property, a CSV column, a GLB attribute")
      .def(
          "remove_attribute",
          [](const py::object& self, const std::string& name) {
            PointSet& s = setOf(self);
            checkNotInUse(s, "remove_attribute");
            Dimension* d = s.dimensions.find(name);
            if (!d) throw py::key_error(name);
            retireKeepingViews(self, d->bytes);  // views of it stay valid
            s.dimensions.remove(name);
          },
          py::arg("name"), "Removes attribute `name` (KeyError when the set has none of that name)")
      .def_property_readonly("has_z", [](const py::object& self) { return setOf(self).hasZ(); },
                             "Whether writers write z (False for a 2D set)")
      .def_property(
          "z_up", [](const py::object& self) { return setOf(self).z_up; },
          [](const py::object& self, bool z_up) { setOf(self).z_up = z_up; },
          "The source says z is up (LAS): render's fitted views use it")
      .def_property(
          "crs",
          [](const py::object& self) -> py::object {
            const PointSet& s = setOf(self);
            std::string text = s.crs, why_not;
            if (text.empty() && s.las) text = lasSourceWkt(*s.las, why_not);
            if (text.empty()) return py::none();
            // Bytes that are not UTF-8 (a PLY header's hex may spell any) as surrogates, not an error.
            return py::reinterpret_steal<py::object>(
                PyUnicode_DecodeUTF8(text.data(), static_cast<Py_ssize_t>(text.size()), "surrogateescape"));
          },
          [](const py::object& self, const py::object& crs) {
            PointSet& s = setOf(self);
            if (!crs.is_none() && !py::isinstance<py::str>(crs)) throw py::type_error("crs: a str or None");
            // What the getter gives back (bytes that are not UTF-8 as surrogates) sets the same bytes.
            std::string text;
            if (!crs.is_none()) {
              PyObject* bytes = PyUnicode_AsEncodedString(crs.ptr(), "utf-8", "surrogateescape");
              if (!bytes) throw py::error_already_set();
              text = py::reinterpret_steal<py::bytes>(bytes).cast<std::string>();
            }
            s.crs = std::move(text);
            if (s.las)  // the source's records give way to it
              std::erase_if(s.las->vlrs, [](const LasVlr& vlr) { return isLasCrsRecord(vlr); });
          },
          "The coordinate system the source states, as text (an E57 file's coordinateMetadata, a LAS file's\n"
          "records as WKT, made by PROJ from GeoTIFF keys), or None. Set it (WKT, or any text: E57, PLY and\n"
          "PCD keep it as it is, LAS takes what PROJ makes WKT of, as convert's --crs) or None to state none;\n"
          "it replaces a LAS source's records")
      .def_property(
          "viewpoint",
          [](const py::object& self) { return viewpointObject(setOf(self).viewpoint); },
          [](const py::object& self, const std::optional<std::vector<double>>& pose) {
            setOf(self).viewpoint = viewpointOf(pose, "viewpoint");
          },
          "A PCD source's VIEWPOINT (tx, ty, tz, qw, qx, qy, qz), the sensor's pose, or None: not applied to\n"
          "the positions, written back to a PCD output (set None after moving the points into the world)")
      .def("copy", [](const py::object& self) { return std::make_shared<PointSet>(setOf(self)); }, "A deep copy")
      .def("__copy__", [](const py::object& self) { return std::make_shared<PointSet>(setOf(self)); })
      .def("__deepcopy__",
           [](const py::object& self, const py::dict&) { return std::make_shared<PointSet>(setOf(self)); })
      // Pickled whole (multiprocessing, joblib): every array as its bytes, the source's facts and a
      // LAS source's frame and records, so the copy writes the files the set writes.
      .def(py::pickle([](const py::object& self) { return pointSetState(setOf(self)); }, &pointSetFromState))
      .def("__repr__", [](const py::object& self) -> std::string {
        const PointSet* held = nullptr;
        try {
          held = &setOf(self);
        } catch (const py::type_error&) {  // a repr that raises hides the object in a debugger
          return "<dpoint.PointSet: holds nothing (made by __new__ without __init__)>";
        }
        const PointSet& s = *held;
        return "<dpoint.PointSet: " + std::to_string(s.size()) + " points" + (s.hasColors() ? ", colours" : "") +
               (s.isMesh() ? ", " + std::to_string(s.triangles.size() / 3) + " triangles" : "") +
               (s.hasZ() ? "" : ", 2D") + ">";
      });

  m.def("_memory_size", [](const std::string& name, const py::object& value) { return take(memoryOption(name, value)); });

  m.def(
      "sample",
      [](const py::object& mesh, uint64_t count, const std::string& method, uint64_t seed,
         unsigned threads, const py::object& max_memory, bool progress) {
        return sampleMesh(&setOf(mesh), "", count, method, seed, threads, max_memory, progress);
      },
      py::arg("mesh"), py::arg("count"), py::kw_only(), py::arg("method") = "uniform", py::arg("seed") = uint64_t{0},
      py::arg("threads") = 0u, py::arg("max_memory") = py::none(), py::arg("progress") = false,
      R"(count points on a mesh's surface, as `dpoint convert MESH --sample N` makes them.

method: uniform (independent points, uniform by area), poisson (an even sample: weighted sample
elimination from 5 x count uniform points, as Open3D's sample_points_poisson_disk) or stratified
(each triangle its share of the points, spread evenly in it). Colours and the
normals (attributes nx, ny, nz) are interpolated over each triangle; a glTF file given by its path
is read with its base-colour textures, which colour the samples. The same seed gives the same
points on any thread count. A set without triangles raises ValueError.)");
  // dpoint.sample of a file: read with its base-colour textures, which then colour the samples.
  m.def(
      "_sample_file",
      [](const std::string& path, uint64_t count, const std::string& method, uint64_t seed, unsigned threads,
         const py::object& max_memory, bool progress) {
        return sampleMesh(nullptr, path, count, method, seed, threads, max_memory, progress);
      },
      py::arg("path"), py::arg("count"), py::kw_only(), py::arg("method") = "uniform", py::arg("seed") = uint64_t{0},
      py::arg("threads") = 0u, py::arg("max_memory") = py::none(), py::arg("progress") = false);

  m.def(
      "read",
      [](const std::string& path, unsigned threads, bool allow_nonfinite, const std::string& colors,
         const py::object& max_memory, int scene, bool all_scenes, uint64_t max_points,
         const std::optional<std::vector<std::string>>& columns, bool progress) {
        return readFile(path, threads, allow_nonfinite, colors, max_memory, scene, all_scenes, max_points, columns,
                        progress);
      },
      py::arg("path"), py::kw_only(), py::arg("threads") = 0u, py::arg("allow_nonfinite") = false,
      py::arg("colors") = "auto", py::arg("max_memory") = py::none(), py::arg("scene") = -1,
      py::arg("all_scenes") = false, py::arg("max_points") = uint64_t{0}, py::arg("columns") = py::none(),
      py::arg("progress") = false,
      R"(Reads a .csv (or .xyz, .txt, .asc, .pts, .ptx), .e57, .ply, .pcd, .las, .laz, .glb or .gltf file (by extension) as `dpoint convert` does.

colors: LAS colour source (auto, rgb, intensity, classification, none); other formats take auto,
rgb or none. scene / all_scenes: glTF scenes (as --scene, --all-scenes). max_memory: bytes or
"8G" (default: half of RAM). max_points: refuse a larger set (MemoryError). columns: text files,
what each column holds, "x,y,z,-,intensity" or a list of the names (as --columns; "-" skips one).
progress: lines on stderr.)");

  m.def(
      "write",
      [](const py::object& points_object, const std::string& path, int decimals, bool ply_ascii,
         const std::optional<std::string>& ply_colors, const std::optional<std::string>& pcd_encoding,
         std::optional<double> las_scale,
         const std::optional<std::string>& crs, const std::string& order, bool no_colors,
         const std::string& color_format, bool unique, unsigned threads, const py::object& max_memory, bool progress) {
        const PointSet& points = setOf(points_object);
        // As convert's --decimals (0..100; -1 here: shortest round trip) and --las-scale (> 0), whatever the format.
        if (decimals < -1 || decimals > 100)
          raise(Error{"decimals: " + std::to_string(decimals) + " is not -1 (shortest round trip) or 0..100",
                      ExitCode::kUsage});
        if (las_scale && !(std::isfinite(*las_scale) && *las_scale > 0.0))
          raise(Error{"las_scale " + formatNumber(*las_scale) + ": must be a finite number above 0", ExitCode::kUsage});
        // None: not given (as the CLI's options, given is refused for another format, even as the default).
        const std::optional<PlyColorType> ply_color_type = parsePlyColorType(ply_colors.value_or("auto"));
        if (!ply_color_type)
          raise(Error{"ply_colors: '" + *ply_colors + "' is not auto, uchar, ushort or float", ExitCode::kUsage});
        if (color_format != "linear" && color_format != "srgb8")
          raise(Error{"color_format: '" + color_format + "' is not linear or srgb8", ExitCode::kUsage});
        const PointOrder point_order = take(parsePointOrder("order", order));
        const PcdEncoding pcd = take(parsePcdEncoding(pcd_encoding.value_or("binary")));
        const uint64_t limit = take(memoryOption("max_memory", max_memory));
        check(formatOf(path).ok() ? okStatus() : Status(formatOf(path).error()));
        // As convert's, named as its flags (the module's write names them as keywords).
        check(checkFormatOptionsUsed(path, {decimals >= 0, ply_ascii, ply_colors.has_value(), pcd_encoding.has_value(),
                                            las_scale.has_value(), crs.has_value()}));
        std::string crs_wkt;  // as convert's --crs
        if (crs) {
          Result<std::string> wkt = crsAsWkt(*crs, "crs");
          if (!wkt) raise(wkt.error());
          crs_wkt = std::move(*wkt);
        }
        std::vector<std::string> notices;  // what the file cannot hold as given: warnings, as the CLI's notes
        const SetInUse in_use(&points);
        check(released([&] {
          Progress bar(progressFile(progress), "write");
          WriteOptions w;
          w.notices = &notices;
          w.threads = threads, w.decimals = decimals, w.progress = &bar, w.las_scale = las_scale.value_or(0.0);
          w.las_crs = crs_wkt;
          w.ply_encoding = ply_ascii ? PlyEncoding::kAscii : PlyEncoding::kBinary;
          w.ply_colors = *ply_color_type;
          w.pcd_encoding = pcd;
          const ColorFilters colors{no_colors, color_format == "srgb8"};
          if (!colors.drop && !colors.srgb8 && !unique && point_order == PointOrder::kInput)
            return writePoints(path, points, w);
          PointSet copy = points;  // the caller's set stays as it is
          if (Status s = filterPoints(copy, colors, unique, point_order, limit, threads, &bar); !s) return s;
          return writePoints(path, copy, w);
        }));
        warnAtCaller(notices);
      },
      py::arg("points"), py::arg("path"), py::kw_only(), py::arg("decimals") = -1, py::arg("ply_ascii") = false,
      py::arg("ply_colors") = std::nullopt, py::arg("pcd_encoding") = std::nullopt, py::arg("las_scale") = std::nullopt, py::arg("crs") = std::nullopt,
      py::arg("order") = "input",
      py::arg("no_colors") = false, py::arg("color_format") = "linear", py::arg("unique") = false,
      py::arg("threads") = 0u, py::arg("max_memory") = py::none(), py::arg("progress") = false,
      R"(Writes a set as .csv (.xyz, .txt, .asc, .pts, .ptx), .ply, .pcd, .glb, .las, .laz or .e57 (by extension), whole or not at all, as `dpoint convert` does.

decimals: CSV fixed digits (-1: shortest round trip). ply_ascii, ply_colors (None or auto: ushort for 16-bit colours, else uchar; uchar; ushort; float),
pcd_encoding (None: binary; ascii, binary or binary_compressed),
las_scale (LAS coordinate step; None: a LAS source's own, else chosen from the data as convert does),
crs (LAS/LAZ/COPC, E57, PLY and PCD: "EPSG:32633", WKT or a .prj file's path, as convert's --crs; None: the source's), order (input or morton), no_colors, color_format (linear or
srgb8), unique: as convert's options; they act on a copy, never on `points`.)");
}

}  // namespace dpoint::python
