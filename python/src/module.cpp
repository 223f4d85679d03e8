// The Python module stereoguard._stereoguard (docs/python.md): a thin layer over the pipeline
// layer's setup (pipeline/setup.hpp), its sequential detector (pipeline/sequential.hpp) and
// pipeline::run. It converts arrays and events; it holds no detection logic.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <condition_variable>
#include <deque>
#include <exception>
#include <mutex>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <string>
#include <thread>

#include "sg/core/error.hpp"
#include "sg/io/events.hpp"
#include "sg/io/stereo_folder.hpp"
#include "sg/pipeline/sequential.hpp"
#include "sg/pipeline/setup.hpp"

namespace py = pybind11;

namespace sg::python {
namespace {

/// A JSON value as the Python object json.loads would give.
py::object to_python(const nlohmann::json& j) {
  switch (j.type()) {
    case nlohmann::json::value_t::null:
      return py::none();
    case nlohmann::json::value_t::boolean:
      return py::bool_(j.get<bool>());
    case nlohmann::json::value_t::number_integer:
      return py::int_(j.get<std::int64_t>());
    case nlohmann::json::value_t::number_unsigned:
      return py::int_(j.get<std::uint64_t>());
    case nlohmann::json::value_t::number_float:
      return py::float_(j.get<double>());
    case nlohmann::json::value_t::string:
      return py::str(j.get<std::string>());
    case nlohmann::json::value_t::array: {
      py::list list;
      for (const auto& item : j) list.append(to_python(item));
      return list;
    }
    case nlohmann::json::value_t::object: {
      py::dict dict;
      for (const auto& [key, value] : j.items()) dict[py::str(key)] = to_python(value);
      return dict;
    }
    default:
      return py::none();
  }
}

std::string shape_text(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) s += (i ? ", " : "") + std::to_string(a.shape(i));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

/// An owned CV_8UC1 image from a uint8 array (H, W) (copied) or (H, W, 3) BGR (converted to gray
/// as OpenCV's COLOR_BGR2GRAY). ValueError naming `name` and the expected form otherwise.
cv::Mat gray_image(const py::array& array, const char* name) {
  const bool shaped = array.ndim() == 2 || (array.ndim() == 3 && array.shape(2) == 3);
  if (!array.dtype().is(py::dtype::of<std::uint8_t>()) || !shaped || array.size() == 0) {
    throw py::value_error(std::string(name) +
                          ": expected a non-empty uint8 array of shape (H, W) (gray) or (H, W, 3) "
                          "(BGR), got " + std::string(py::str(array.dtype())) + " " +
                          shape_text(array));
  }
  const auto contiguous = py::array_t<std::uint8_t, py::array::c_style>::ensure(array);
  const int rows = static_cast<int>(contiguous.shape(0));
  const int cols = static_cast<int>(contiguous.shape(1));
  const cv::Mat view(rows, cols, array.ndim() == 2 ? CV_8UC1 : CV_8UC3,
                     const_cast<std::uint8_t*>(contiguous.data()));
  cv::Mat gray;
  if (view.channels() == 3) {
    cv::cvtColor(view, gray, cv::COLOR_BGR2GRAY);
  } else {
    gray = view.clone();
  }
  return gray;
}

/// A float32 numpy array over `mat` (CV_32F or CV_32FC2) without a copy: the array keeps a share
/// of the cv::Mat alive. None for an empty map.
py::object share_map(const cv::Mat& mat) {
  if (mat.empty()) return py::none();
  auto* owner = new cv::Mat(mat);
  py::capsule keep(owner, [](void* p) { delete static_cast<cv::Mat*>(p); });
  const auto step = static_cast<py::ssize_t>(mat.step[0]);
  constexpr py::ssize_t f = sizeof(float);
  if (mat.channels() == 1) {
    return py::array_t<float>({mat.rows, mat.cols}, {step, f}, mat.ptr<float>(), keep);
  }
  const py::ssize_t channels = mat.channels();
  return py::array_t<float>({static_cast<py::ssize_t>(mat.rows), static_cast<py::ssize_t>(mat.cols),
                             channels},
                            {step, f * channels, f}, mat.ptr<float>(), keep);
}

std::optional<std::string> optional_string(const py::object& o) {
  if (o.is_none()) return std::nullopt;
  return o.cast<std::string>();
}

/// stereoguard.Detector: the detector one frame at a time (pipeline::SequentialDetector), with the
/// CLI's options for the camera (make_run_options with the camera: core::adapt_to_camera). The
/// camera's size comes from its dict, else from the first frame (a camera.yaml gives none).
class Detector {
 public:
  Detector(const py::object& camera, const std::string& config, const py::object& platform) {
    options_.config = config;
    options_.platform = optional_string(platform);
    if (py::isinstance<py::str>(camera)) {
      camera_file_ = camera.cast<std::string>();
      io::read_camera_yaml(camera_file_, cv::Size(1, 1));  // a missing or broken file fails here
    } else if (py::isinstance<py::dict>(camera)) {
      read_camera_dict(camera.cast<py::dict>());
    } else {
      throw py::type_error("camera: expected a camera.yaml path or a dict with focal_px, "
                           "baseline_m (and cx, cy, width, height, fps)");
    }
    if (!config.empty()) io::config_platform(config);  // a missing or broken config fails here
    if (sized_) start(cv::Size(camera_.width, camera_.height));
  }

  py::object process(const py::array& left, const py::array& right, double time_s) {
    core::StereoFrame frame;
    frame.index = next_index_;
    frame.time_s = time_s;
    frame.left = gray_image(left, "left");
    frame.right = gray_image(right, "right");
    if (frame.left.size() != frame.right.size()) {
      throw py::value_error("left and right differ in size: " + shape_text(left) + " and " +
                            shape_text(right));
    }
    nlohmann::json event;
    {
      py::gil_scoped_release release;
      if (!detector_) start(frame.left.size());
      event = io::detection_to_json(detector_->process(frame), false);
    }
    ++next_index_;
    return to_python(event);
  }

  py::object disparity() const {
    return detector_ ? share_map(detector_->disparity()) : py::none();
  }
  py::object flow() const { return detector_ ? share_map(detector_->flow()) : py::none(); }

 private:
  void read_camera_dict(const py::dict& d) {
    const char* known[] = {"focal_px", "baseline_m", "cx", "cy", "width", "height", "fps"};
    for (const auto& item : d) {
      const std::string key = py::str(item.first);
      if (std::find(std::begin(known), std::end(known), key) == std::end(known)) {
        throw core::InputError("camera." + key +
                               ": unknown key (known: focal_px, baseline_m, cx, cy, width, "
                               "height, fps)");
      }
    }
    for (const char* required : {"focal_px", "baseline_m"}) {
      if (!d.contains(required)) {
        throw core::InputError(std::string("camera.") + required + ": missing");
      }
    }
    camera_.focal_px = d["focal_px"].cast<double>();
    camera_.baseline_m = d["baseline_m"].cast<double>();
    if (d.contains("cx")) cx_ = d["cx"].cast<double>();
    if (d.contains("cy")) cy_ = d["cy"].cast<double>();
    if (d.contains("fps")) camera_.fps = d["fps"].cast<double>();
    if (d.contains("width") != d.contains("height")) {
      throw core::InputError(
          "camera: give width and height together, or neither (the first frame's size is taken)");
    }
    if (d.contains("width")) {
      camera_.width = d["width"].cast<int>();
      camera_.height = d["height"].cast<int>();
      sized_ = true;
    }
  }

  /// The camera at `size` (cx, cy default to the image centre), the run options made for it and
  /// validated, and the detector.
  void start(cv::Size size) {
    if (!camera_file_.empty()) {
      camera_ = io::read_camera_yaml(camera_file_, size);
    } else {
      camera_.width = size.width;
      camera_.height = size.height;
      camera_.cx = cx_.value_or((size.width - 1) / 2.0);
      camera_.cy = cy_.value_or((size.height - 1) / 2.0);
      core::throw_if_invalid(core::validate(camera_), "invalid camera");
    }
    const pipeline::RunOptions run = pipeline::make_run_options(options_, "", nullptr, &camera_);
    core::throw_if_invalid(pipeline::validate(run, camera_), "invalid parameters");
    detector_.emplace(run.params, camera_);
  }

  pipeline::DetectorOptions options_;
  std::string camera_file_;
  core::Camera camera_;
  std::optional<double> cx_, cy_;
  bool sized_ = false;
  std::optional<pipeline::SequentialDetector> detector_;
  int next_index_ = 0;
};

/// The events of one pipeline::run, delivered to Python as an iterator: the run goes on in a
/// background thread and hands each event, as JSON, through a bounded queue (the run waits when
/// Python falls kExpectedAhead events behind). The GIL is released while Python waits, and the
/// run's threads never take it. Dropping the iterator stops the run.
class EventStream {
 public:
  static constexpr std::size_t kExpectedAhead = 64;

  explicit EventStream(pipeline::PreparedRun prepared) : prepared_(std::move(prepared)) {
    worker_ = std::thread([this] { work(); });
  }
  ~EventStream() {
    {
      std::lock_guard lock(mutex_);
      cancelled_ = true;
    }
    changed_.notify_all();
    py::gil_scoped_release release;
    worker_.join();
  }

  py::object next() {
    nlohmann::json event;
    {
      py::gil_scoped_release release;
      std::unique_lock lock(mutex_);
      changed_.wait(lock, [this] { return !queue_.empty() || done_; });
      if (queue_.empty()) {
        if (error_) std::rethrow_exception(std::exchange(error_, nullptr));
        throw py::stop_iteration();
      }
      event = std::move(queue_.front());
      queue_.pop_front();
    }
    changed_.notify_all();
    return to_python(event);
  }

  /// The run's summary (RunSummary::to_json) once the run ended, else None.
  py::object summary() {
    std::lock_guard lock(mutex_);
    return done_ && !error_ ? to_python(summary_) : py::object(py::none());
  }

 private:
  struct Cancelled {};

  void work() {
    try {
      const pipeline::RunSummary s = pipeline::run(
          *prepared_.input.source, prepared_.options,
          [this](const core::StereoFrame&, const core::Detection& d) {
            nlohmann::json event = io::detection_to_json(d, false);
            std::unique_lock lock(mutex_);
            changed_.wait(lock, [this] { return queue_.size() < kExpectedAhead || cancelled_; });
            if (cancelled_) throw Cancelled{};
            queue_.push_back(std::move(event));
            lock.unlock();
            changed_.notify_all();
          });
      std::lock_guard lock(mutex_);
      summary_ = s.to_json();
    } catch (const Cancelled&) {
    } catch (...) {
      std::lock_guard lock(mutex_);
      if (!cancelled_) error_ = std::current_exception();
    }
    {
      std::lock_guard lock(mutex_);
      done_ = true;
    }
    changed_.notify_all();
  }

  pipeline::PreparedRun prepared_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<nlohmann::json> queue_;
  bool done_ = false, cancelled_ = false;
  std::exception_ptr error_;
  nlohmann::json summary_;
  std::thread worker_;
};

template <class T>
void take(py::dict& kwargs, const char* key, T& to) {
  if (!kwargs.contains(key)) return;
  const py::object value = kwargs[key];
  PyDict_DelItemString(kwargs.ptr(), key);
  if (!value.is_none()) to = value.cast<T>();
}

/// A workers / tiles argument: an int or "auto", as the CLI's text.
void take_count(py::dict& kwargs, const char* key, std::optional<std::string>& to) {
  if (!kwargs.contains(key)) return;
  const py::object value = kwargs[key];
  PyDict_DelItemString(kwargs.ptr(), key);
  if (!value.is_none()) to = std::string(py::str(value));
}

/// run(**inputs and options): the CLI's `run` inputs and detector options by their flag names
/// (scenario, input, left, right, sbs, kitti, kitti_color, euroc, camera, calib, focal, baseline,
/// cx, cy, input_fps; config, platform, detector, workers, tiles, tokens, threads, fps, scale).
std::unique_ptr<EventStream> start_run(py::kwargs kwargs_in) {
  py::dict kwargs(kwargs_in);
  pipeline::InputOptions in;
  in.fallback_scenario = "head-on";
  pipeline::DetectorOptions d;
  std::optional<double> scale;
  io::SourceSpec& s = in.spec;
  take(kwargs, "scenario", in.scenario);
  take(kwargs, "input", in.input);
  take(kwargs, "left", s.left);
  take(kwargs, "right", s.right);
  take(kwargs, "sbs", in.sbs);
  take(kwargs, "kitti", s.kitti);
  take(kwargs, "kitti_color", s.kitti_color);
  take(kwargs, "euroc", s.euroc);
  take(kwargs, "camera", s.camera);
  take(kwargs, "calib", s.calib);
  take(kwargs, "focal", s.focal_px);
  take(kwargs, "baseline", s.baseline_m);
  take(kwargs, "cx", s.cx);
  take(kwargs, "cy", s.cy);
  take(kwargs, "input_fps", s.input_fps);
  take(kwargs, "config", d.config);
  take(kwargs, "platform", d.platform);
  take(kwargs, "detector", d.mode);
  take_count(kwargs, "workers", d.workers);
  take_count(kwargs, "tiles", d.tiles);
  take(kwargs, "tokens", d.tokens);
  take(kwargs, "threads", d.threads);
  take(kwargs, "fps", d.fps);
  take(kwargs, "scale", scale);
  if (!kwargs.empty()) {
    throw py::type_error("run(): unexpected keyword argument '" +
                         std::string(py::str(kwargs.begin()->first)) + "'");
  }
  if (!in.scenario.empty() && !in.input.empty()) {
    throw core::InputError("give one input: scenario or input");
  }
  std::optional<pipeline::PreparedRun> prepared;
  {
    py::gil_scoped_release release;
    prepared.emplace(pipeline::prepare_run(in, d, scale));
    // main() of the CLI tunes glibc so that the touched heap stays; a Python process does not.
    prepared->options.prefault_heap = false;
  }
  return std::make_unique<EventStream>(std::move(*prepared));
}

}  // namespace
}  // namespace sg::python

PYBIND11_MODULE(_stereoguard, m) {
  using namespace sg::python;
  m.doc() = "stereoguard: stereo-camera obstacle detection (docs/python.md)";
  m.attr("version") = SG_VERSION;
  py::register_exception<sg::core::InputError>(m, "Error", PyExc_ValueError);

  py::class_<Detector>(m, "Detector")
      .def(py::init<const py::object&, const std::string&, const py::object&>(), py::arg("camera"),
           py::arg("config") = "", py::arg("platform") = py::none())
      .def("process", &Detector::process, py::arg("left"), py::arg("right"), py::arg("t_s"))
      .def_property_readonly("disparity", &Detector::disparity)
      .def_property_readonly("flow", &Detector::flow);

  py::class_<EventStream>(m, "EventStream")
      .def("__iter__", [](EventStream& s) -> EventStream& { return s; })
      .def("__next__", &EventStream::next)
      .def_property_readonly("summary", &EventStream::summary);

  m.def("_run", &start_run);
}
