#include "synth/synth_truth.h"

#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>

namespace bouncefit {

using nlohmann::json;

std::filesystem::path SynthTruthPathFor(const std::filesystem::path& clip) {
  auto p = clip;
  p.replace_extension(".truth.json");
  return p;
}

void WriteSynthTruth(const SynthTruth& t, const std::filesystem::path& path) {
  using ojson = nlohmann::ordered_json;  // keeps the fields in the documented order
  ojson j;
  j["format"] = "bouncefit-synth-truth";
  j["version"] = t.version;
  j["clip"] = t.clip;
  j["fps"] = t.fps;
  j["width"] = t.width;
  j["height"] = t.height;
  j["frames"] = t.frame_count;
  j["px_per_m"] = t.px_per_m;
  j["roll_deg"] = t.roll_deg;
  j["down"] = {t.down_x, t.down_y};
  j["rotation_center_px"] = {t.center_x, t.center_y};
  j["floor"] = {{"y_unrolled_px", t.floor_y_unrolled_px},
                {"offset_px", t.floor_offset_px},
                {"point_px", {t.floor_point_x, t.floor_point_y}},
                {"direction", {t.floor_dir_x, t.floor_dir_y}}};
  j["ball"] = {{"preset", t.ball},
               {"radius_m", t.radius_m},
               {"radius_px", t.radius_px},
               {"mass_kg", t.mass_kg},
               {"restitution", t.restitution},
               {"restitution_per_mps", t.restitution_per_mps},
               {"drag_coefficient", t.drag_coefficient},
               {"color_bgr", {t.ball_color_bgr[0], t.ball_color_bgr[1], t.ball_color_bgr[2]}}};
  j["physics"] = {{"trajectory", t.trajectory},
                  {"g_mps2", t.g_mps2},
                  {"drop_height_m", t.drop_height_m},
                  {"launch_up_mps", t.launch_up_mps},
                  {"launch_right_mps", t.launch_right_mps}};
  j["render"] = {{"exposure_s", t.exposure_s},
                 {"blur_samples", t.blur_samples},
                 {"noise_sigma", t.noise_sigma},
                 {"seed", t.seed},
                 {"distractor", t.distractor},
                 {"camera_jitter_px", t.camera_jitter_px},
                 {"camera_sway_px", t.camera_sway_px}};
  j["release_t_s"] = t.release_t_s;
  j["impact_times_s"] = t.impact_times_s;
  j["first_apex"] = t.first_apex;
  j["apex_times_s"] = t.apex_times_s;
  j["apex_heights_m"] = t.apex_heights_m;
  if (t.timeline.Variable()) {
    j["timeline"] = {{"slow_motion", t.timeline.slow_motion},
                     {"slow_from_s", t.timeline.slow_from_s},
                     {"slow_to_s", t.timeline.slow_to_s},
                     {"slow_ramp_s", t.timeline.slow_ramp_s},
                     {"vfr_min_fps", t.timeline.vfr_min_fps},
                     {"impact_file_times_s", t.impact_file_times_s},
                     {"apex_file_times_s", t.apex_file_times_s}};
  }
  j["comes_to_rest"] = t.comes_to_rest;
  j["rest_t_s"] = t.comes_to_rest ? ojson(t.rest_t_s) : ojson(nullptr);
  if (t.has_sound)
    j["sound"] = {{"sample_rate_hz", t.sound_sample_rate},
                  {"offset_s", t.sound_offset_s},
                  {"chatter", t.sound_chatter},
                  {"hum", t.sound_hum},
                  {"room_noise_rms", t.sound_noise_rms},
                  {"chatter_rms", t.sound_chatter ? t.sound_chatter_rms : 0.0},
                  {"hum_rms", t.sound_hum ? t.sound_hum_rms : 0.0},
                  {"click_at_1mps", t.sound_click_at_1mps},
                  {"click_exponent", t.sound_click_exponent},
                  {"impact_speeds_mps", t.impact_speeds_mps},
                  {"extra_clicks_s", t.extra_clicks_s}};
  if (!t.drops.empty()) {
    j["camera"] = {{"focal_px", t.camera_focal_px}, {"height_m", t.camera_height_m}};
    ojson drops = ojson::array();
    for (const SynthTruthDrop& d : t.drops)
      drops.push_back({{"distance_m", d.distance_m},
                       {"approach_mps", d.approach_mps},
                       {"px_per_m", d.px_per_m},
                       {"radius_px", d.radius_px},
                       {"floor_offset_px", d.floor_offset_px},
                       {"drop_height_m", d.drop_height_m},
                       {"release_t_s", d.release_t_s},
                       {"impact_times_s", d.impact_times_s},
                       {"apex_times_s", d.apex_times_s},
                       {"apex_heights_m", d.apex_heights_m},
                       {"rest_t_s", d.rest_t_s}});
    j["drops"] = drops;
  }
  ojson frames = ojson::array();
  for (const auto& f : t.frames) {
    frames.push_back({{"i", f.index},
                      {"t_s", f.t_s},
                      {"cx", f.cx},
                      {"cy", f.cy},
                      {"height_m", f.height_m},
                      {"fully_in_view", f.fully_in_view}});
    if (t.timeline.Variable()) frames.back().push_back({"file_t_s", f.file_t_s});
    if (f.camera_dx != 0 || f.camera_dy != 0)
      frames.back().push_back({"camera_dx", f.camera_dx}), frames.back().push_back({"camera_dy", f.camera_dy});
  }

  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write truth file " + path.string());
  // One line per top-level field, then one line per frame: readable and diffable.
  out << "{";
  bool first = true;
  for (const auto& [key, value] : j.items()) {
    out << (first ? "\n " : ",\n ") << ojson(key).dump() << ": " << value.dump();
    first = false;
  }
  out << ",\n \"per_frame\": [";
  for (size_t i = 0; i < frames.size(); ++i)
    out << (i ? ",\n  " : "\n  ") << frames[i].dump();
  out << "\n ]\n}\n";
  if (!out) throw std::runtime_error("error writing truth file " + path.string());
}

namespace {

template <typename T>
T Get(const json& j, const char* key, const std::string& where) {
  if (!j.is_object() || !j.contains(key))
    throw std::runtime_error(where + ": missing '" + key + "'");
  try {
    return j.at(key).get<T>();
  } catch (const json::exception&) {
    throw std::runtime_error(where + ": bad value for '" + key + "'");
  }
}

}  // namespace

SynthTruth LoadSynthTruth(const std::filesystem::path& path) {
  const std::string where = path.string();
  std::ifstream in(path);
  if (!in) throw std::runtime_error(where + ": cannot open truth file");
  json j;
  try {
    j = json::parse(in);
  } catch (const json::parse_error& e) {
    throw std::runtime_error(where + ": not valid JSON (byte " + std::to_string(e.byte) + ")");
  }
  if (!j.is_object() || j.value("format", "") != "bouncefit-synth-truth")
    throw std::runtime_error(where + ": not a bouncefit synth truth file");
  SynthTruth t;
  t.version = Get<int>(j, "version", where);
  if (t.version != 1)
    throw std::runtime_error(where + ": unsupported truth version " + std::to_string(t.version));
  t.clip = Get<std::string>(j, "clip", where);
  t.fps = Get<double>(j, "fps", where);
  t.width = Get<int>(j, "width", where);
  t.height = Get<int>(j, "height", where);
  t.frame_count = Get<int>(j, "frames", where);
  t.px_per_m = Get<double>(j, "px_per_m", where);
  t.roll_deg = Get<double>(j, "roll_deg", where);
  auto down = Get<std::vector<double>>(j, "down", where);
  auto center = Get<std::vector<double>>(j, "rotation_center_px", where);
  if (down.size() != 2 || center.size() != 2)
    throw std::runtime_error(where + ": 'down' and 'rotation_center_px' need 2 numbers");
  t.down_x = down[0], t.down_y = down[1];
  t.center_x = center[0], t.center_y = center[1];
  const json floor = Get<json>(j, "floor", where);
  t.floor_y_unrolled_px = Get<double>(floor, "y_unrolled_px", where + " floor");
  t.floor_offset_px = Get<double>(floor, "offset_px", where + " floor");
  auto fp = Get<std::vector<double>>(floor, "point_px", where + " floor");
  auto fd = Get<std::vector<double>>(floor, "direction", where + " floor");
  if (fp.size() != 2 || fd.size() != 2)
    throw std::runtime_error(where + ": floor 'point_px' and 'direction' need 2 numbers");
  t.floor_point_x = fp[0], t.floor_point_y = fp[1];
  t.floor_dir_x = fd[0], t.floor_dir_y = fd[1];

  const json ball = Get<json>(j, "ball", where);
  t.ball = Get<std::string>(ball, "preset", where + " ball");
  t.radius_m = Get<double>(ball, "radius_m", where + " ball");
  t.radius_px = Get<double>(ball, "radius_px", where + " ball");
  t.mass_kg = Get<double>(ball, "mass_kg", where + " ball");
  t.restitution = Get<double>(ball, "restitution", where + " ball");
  t.restitution_per_mps = Get<double>(ball, "restitution_per_mps", where + " ball");
  t.drag_coefficient = Get<double>(ball, "drag_coefficient", where + " ball");
  auto color = Get<std::vector<double>>(ball, "color_bgr", where + " ball");
  if (color.size() != 3) throw std::runtime_error(where + ": ball 'color_bgr' needs 3 numbers");
  for (int i = 0; i < 3; ++i) t.ball_color_bgr[i] = color[i];

  const json physics = Get<json>(j, "physics", where);
  t.trajectory = Get<std::string>(physics, "trajectory", where + " physics");
  t.g_mps2 = Get<double>(physics, "g_mps2", where + " physics");
  t.drop_height_m = Get<double>(physics, "drop_height_m", where + " physics");
  // Absent in files written before throws existed: a drop from rest.
  t.launch_up_mps = physics.value("launch_up_mps", 0.0);
  t.launch_right_mps = physics.value("launch_right_mps", 0.0);

  const json render = Get<json>(j, "render", where);
  t.exposure_s = Get<double>(render, "exposure_s", where + " render");
  t.blur_samples = Get<int>(render, "blur_samples", where + " render");
  t.noise_sigma = Get<double>(render, "noise_sigma", where + " render");
  t.seed = Get<unsigned long long>(render, "seed", where + " render");
  t.distractor = Get<bool>(render, "distractor", where + " render");
  // Absent in files written before held cameras existed: a still camera.
  t.camera_jitter_px = render.value("camera_jitter_px", 0.0);
  t.camera_sway_px = render.value("camera_sway_px", 0.0);

  t.release_t_s = Get<double>(j, "release_t_s", where);
  t.impact_times_s = Get<std::vector<double>>(j, "impact_times_s", where);
  t.first_apex = j.value("first_apex", 0);
  t.apex_times_s = Get<std::vector<double>>(j, "apex_times_s", where);
  t.apex_heights_m = Get<std::vector<double>>(j, "apex_heights_m", where);
  if (t.apex_times_s.size() != t.apex_heights_m.size())
    throw std::runtime_error(where + ": apex_times_s and apex_heights_m differ in length");
  if (j.contains("timeline")) {
    const json tl = Get<json>(j, "timeline", where);
    t.timeline.slow_motion = Get<double>(tl, "slow_motion", where + " timeline");
    t.timeline.slow_from_s = Get<double>(tl, "slow_from_s", where + " timeline");
    t.timeline.slow_to_s = Get<double>(tl, "slow_to_s", where + " timeline");
    t.timeline.slow_ramp_s = tl.value("slow_ramp_s", 0.0);
    t.timeline.vfr_min_fps = Get<double>(tl, "vfr_min_fps", where + " timeline");
    t.impact_file_times_s = Get<std::vector<double>>(tl, "impact_file_times_s", where + " timeline");
    t.apex_file_times_s = Get<std::vector<double>>(tl, "apex_file_times_s", where + " timeline");
  }
  t.comes_to_rest = Get<bool>(j, "comes_to_rest", where);
  if (t.comes_to_rest) t.rest_t_s = Get<double>(j, "rest_t_s", where);
  if (j.contains("sound")) {
    const json sound = Get<json>(j, "sound", where);
    t.has_sound = true;
    t.sound_sample_rate = Get<int>(sound, "sample_rate_hz", where + " sound");
    t.sound_offset_s = Get<double>(sound, "offset_s", where + " sound");
    t.sound_chatter = Get<bool>(sound, "chatter", where + " sound");
    t.sound_hum = Get<bool>(sound, "hum", where + " sound");
    if (sound.contains("room_noise_rms")) {  // files written before the levels lack them
      t.sound_noise_rms = Get<double>(sound, "room_noise_rms", where + " sound");
      t.sound_chatter_rms = Get<double>(sound, "chatter_rms", where + " sound");
      t.sound_hum_rms = Get<double>(sound, "hum_rms", where + " sound");
      t.sound_click_at_1mps = Get<double>(sound, "click_at_1mps", where + " sound");
      t.sound_click_exponent = Get<double>(sound, "click_exponent", where + " sound");
    }
    t.impact_speeds_mps = Get<std::vector<double>>(sound, "impact_speeds_mps", where + " sound");
    if (sound.contains("extra_clicks_s"))  // files written before extra clicks lack them
      t.extra_clicks_s = Get<std::vector<double>>(sound, "extra_clicks_s", where + " sound");
  }

  if (j.contains("drops")) {
    const json camera = Get<json>(j, "camera", where);
    t.camera_focal_px = Get<double>(camera, "focal_px", where + " camera");
    t.camera_height_m = Get<double>(camera, "height_m", where + " camera");
    const json drops = Get<json>(j, "drops", where);
    if (!drops.is_array()) throw std::runtime_error(where + ": 'drops' is not an array");
    for (size_t i = 0; i < drops.size(); ++i) {
      const std::string dw = where + " drops[" + std::to_string(i) + "]";
      SynthTruthDrop d;
      d.distance_m = Get<double>(drops[i], "distance_m", dw);
      d.approach_mps = drops[i].value("approach_mps", 0.0);
      d.px_per_m = Get<double>(drops[i], "px_per_m", dw);
      d.radius_px = Get<double>(drops[i], "radius_px", dw);
      d.floor_offset_px = Get<double>(drops[i], "floor_offset_px", dw);
      d.drop_height_m = Get<double>(drops[i], "drop_height_m", dw);
      d.release_t_s = Get<double>(drops[i], "release_t_s", dw);
      d.impact_times_s = Get<std::vector<double>>(drops[i], "impact_times_s", dw);
      d.apex_times_s = Get<std::vector<double>>(drops[i], "apex_times_s", dw);
      d.apex_heights_m = Get<std::vector<double>>(drops[i], "apex_heights_m", dw);
      d.rest_t_s = Get<double>(drops[i], "rest_t_s", dw);
      t.drops.push_back(std::move(d));
    }
  }
  const json frames = Get<json>(j, "per_frame", where);
  if (!frames.is_array()) throw std::runtime_error(where + ": 'per_frame' is not an array");
  t.frames.reserve(frames.size());
  for (size_t i = 0; i < frames.size(); ++i) {
    const std::string fw = where + " per_frame[" + std::to_string(i) + "]";
    SynthTruthFrame f;
    f.index = Get<int>(frames[i], "i", fw);
    f.t_s = Get<double>(frames[i], "t_s", fw);
    f.cx = Get<double>(frames[i], "cx", fw);
    f.cy = Get<double>(frames[i], "cy", fw);
    f.height_m = Get<double>(frames[i], "height_m", fw);
    f.fully_in_view = Get<bool>(frames[i], "fully_in_view", fw);
    f.file_t_s = frames[i].value("file_t_s", f.t_s);
    f.camera_dx = frames[i].value("camera_dx", 0.0);
    f.camera_dy = frames[i].value("camera_dy", 0.0);
    t.frames.push_back(f);
  }
  if (static_cast<int>(t.frames.size()) != t.frame_count)
    throw std::runtime_error(where + ": 'frames' says " + std::to_string(t.frame_count) +
                             " but per_frame has " + std::to_string(t.frames.size()));
  return t;
}

}  // namespace bouncefit
