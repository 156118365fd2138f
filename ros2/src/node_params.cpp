#include "kfd/ros2/node_params.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <sstream>

#include "kfd/mrpt/config.h"
#include "kfd/mrpt/default_stages.h"

namespace kfd::ros2 {

namespace {

using Pairs = std::vector<std::pair<std::string, std::string>>;

const char* const kOwnParams[] = {"config",      "odom",       "odom_frame",     "base_frame",
                                  "tf_wait",     "removed_as", "reset_jump",     "queue_size",
                                  "track_topic", "domain_id",  "localhost_only", "scan_qos",
                                  "stats_period"};

bool isOwn(const std::string& name) {
    for (const char* n : kOwnParams)
        if (name == n) return true;
    return false;
}

// A value as ROS 2 reads `-p name:=value`: YAML. A scalar is its text, a list its items
// joined with commas (`pipeline:=[distance, keyframe]`).
std::string valueText(const std::string& name, const YAML::Node& v) {
    if (v.IsScalar()) return v.Scalar();
    if (v.IsSequence()) {
        std::string out;
        for (const auto& item : v) {
            if (!item.IsScalar()) throw ConfigError(name, "a list of lists or maps is not a value");
            out += (out.empty() ? "" : ",") + item.Scalar();
        }
        return out;
    }
    if (v.IsNull()) return "";
    throw ConfigError(name, "a map is not a value (write <stage>.<key>:=value)");
}

std::string parsedText(const std::string& name, const std::string& text) {
    try {
        return valueText(name, YAML::Load(text));
    } catch (const YAML::Exception& e) {
        throw ConfigError(name, "'" + text + "' is not a value: " + e.what());
    }
}

double number(const std::string& key, const std::string& v, double lo, double hi) {
    char* end = nullptr;
    const double d = std::strtod(v.c_str(), &end);
    if (v.empty() || *end != '\0') throw ConfigError(key, "'" + v + "' is not a number");
    if (!std::isfinite(d) || d < lo || d > hi) {
        std::ostringstream s;
        s << v << " is outside [" << lo << ", " << hi << "]";
        throw ConfigError(key, s.str());
    }
    return d;
}

int integer(const std::string& key, const std::string& v, int lo, int hi) {
    const double d = number(key, v, lo, hi);
    if (d != std::floor(d)) throw ConfigError(key, "'" + v + "' is not an integer");
    return static_cast<int>(d);
}

bool boolean(const std::string& key, const std::string& v) {
    if (v == "true" || v == "True" || v == "1") return true;
    if (v == "false" || v == "False" || v == "0") return false;
    throw ConfigError(key, "'" + v + "' is not true or false");
}

// One of the node's own parameters into `c`.
void setOwn(Ros2Config& c, const std::string& key, const std::string& v) {
    if (key == "odom") {
        if (v == "tf")
            c.odometry = Ros2Config::Odometry::Tf;
        else if (v == "topic")
            c.odometry = Ros2Config::Odometry::Topic;
        else if (v == "none")
            c.odometry = Ros2Config::Odometry::None;
        else
            throw ConfigError(key, "'" + v + "' is not tf, topic or none");
    } else if (key == "odom_frame" || key == "base_frame") {
        std::string f = v;
        while (!f.empty() && f.front() == '/') f.erase(0, 1);  // tf2 frames have no leading '/'
        if (f.empty()) throw ConfigError(key, "'" + v + "' names no frame");
        (key == "odom_frame" ? c.odom_frame : c.base_frame) = f;
    } else if (key == "tf_wait") {
        c.tf_wait = number(key, v, 0.0, 10.0);
    } else if (key == "reset_jump") {
        c.reset_jump = number(key, v, 0.0, 1e9);
    } else if (key == "queue_size") {
        c.queue_size = integer(key, v, 1, 1000);
    } else if (key == "track_topic") {
        c.track_topic = v;
    } else if (key == "domain_id") {
        c.domain_id = integer(key, v, 0, 232);  // DDS's port formula allows 0..232
    } else if (key == "localhost_only") {
        c.localhost_only = boolean(key, v);
    } else if (key == "scan_qos") {
        if (v == "best_effort")
            c.scan_reliability = Reliability::BestEffort;
        else if (v == "reliable")
            c.scan_reliability = Reliability::Reliable;
        else
            throw ConfigError(key, "'" + v + "' is not best_effort or reliable");
    } else if (key == "stats_period") {
        c.stats_period = number(key, v, 0.05, 3600.0);
    } else if (key == "removed_as") {
        try {
            c.removed = parseRemovedMark(v);
        } catch (const ConfigError&) {
            throw;
        } catch (const Error& e) {
            throw ConfigError(key, e.what());
        }
    }
}

// The environment's defaults (ROS 2's own variables).
void fromEnvironment(Ros2Config& c) {
    if (const char* d = std::getenv("ROS_DOMAIN_ID"); d && *d)
        c.domain_id = integer("ROS_DOMAIN_ID", d, 0, 232);
    if (const char* l = std::getenv("ROS_LOCALHOST_ONLY"); l && *l)
        c.localhost_only = std::strcmp(l, "1") == 0;
}

// A kfd key: `<stage>.<key>` into that stage's section, others flat.
void addKfdKey(ConfigValues& kfd, const std::string& key, const std::string& v) {
    const auto dot = key.find('.');
    if (dot == std::string::npos) {
        kfd.keys.emplace_back(key, v);
        return;
    }
    const std::string stage = key.substr(0, dot), name = key.substr(dot + 1);
    if (stage.empty() || name.empty() || name.find('.') != std::string::npos)
        throw ConfigError(key, "is not <stage>.<key>");
    for (auto& s : kfd.sections)
        if (s.stage == stage) {
            s.keys.emplace_back(name, v);
            return;
        }
    kfd.sections.push_back(ConfigValues::Section{stage, {{name, v}}});
}

// The parameters of a --params-file: every `ros__parameters` map (of `/**` or any node name),
// nested maps flattened with '.'.
void flatten(const YAML::Node& n, const std::string& prefix, Pairs& out) {
    if (n.IsMap()) {
        for (const auto& kv : n)
            flatten(kv.second,
                    prefix.empty() ? kv.first.Scalar() : prefix + "." + kv.first.Scalar(), out);
        return;
    }
    out.emplace_back(prefix, valueText(prefix, n));
}

Pairs paramsFile(const std::string& path) {
    YAML::Node root;
    try {
        root = YAML::LoadFile(path);
    } catch (const YAML::Exception& e) {
        throw ConfigError("--params-file", path + ": " + e.what());
    }
    Pairs out;
    if (!root.IsMap()) throw ConfigError("--params-file", path + ": not a map of node names");
    for (const auto& node : root) {
        const YAML::Node p = node.second.IsMap() ? node.second["ros__parameters"] : YAML::Node();
        if (!p || !p.IsMap())
            throw ConfigError("--params-file",
                              path + ": '" + node.first.Scalar() + "' has no ros__parameters map");
        flatten(p, "", out);
    }
    return out;
}

std::pair<std::string, std::string> assignment(const std::string& opt, const char* arg) {
    if (!arg) throw ConfigError(opt, "needs name:=value");
    const std::string s = arg;
    const auto at = s.find(":=");
    if (at == std::string::npos || at == 0)
        throw ConfigError(opt, "'" + s + "' is not name:=value");
    return {s.substr(0, at), s.substr(at + 2)};
}

}  // namespace

std::string Ros2Config::ddsTopic(const std::string& name) const {
    std::string t = name;
    for (const auto& [from, to] : remaps)
        if (from == name) t = to;
    if (t.empty() || t[0] != '/') t = (ns.empty() || ns == "/" ? "" : ns) + "/" + t;
    return "rt" + t;
}

Ros2Config ros2Config(const Pairs& params, const Pairs& remaps) {
    Ros2Config c;
    fromEnvironment(c);
    for (const auto& [from, to] : remaps) {
        if (from == "__node")
            c.node_name = to;
        else if (from == "__ns")
            c.ns = to.empty() || to[0] == '/' ? to : "/" + to;
        else
            c.remaps.emplace_back(from, to);
    }
    for (const auto& [key, value] : params)
        if (key == "config") c.config_path = value;
    c.pipeline =
        c.config_path.empty() ? kfdDefaults() : loadConfigFile(c.config_path, "KFD", &c.notes);
    ConfigValues kfd_keys;
    for (const auto& [key, value] : params) {
        if (key == "config") continue;
        if (isOwn(key))
            setOwn(c, key, value);
        else
            addKfdKey(kfd_keys, key, value);
    }
    applyConfig(c.pipeline, kfd_keys, defaultStageRegistry(),
                ConfigSyntax{ConfigSyntax::Ros2Params, "KFD"}, &c.notes);
    validateConfig(c.pipeline, defaultStageRegistry());
    return c;
}

Ros2Args parseRos2Args(int argc, const char* const* argv) {
    Ros2Args a;
    Pairs params, remaps;
    bool ros_args = false;
    for (int i = 1; i < argc; ++i) {
        const std::string s = argv[i];
        const char* next = i + 1 < argc ? argv[i + 1] : nullptr;
        if (s == "--help" || s == "-h") {
            a.help = true;
        } else if (s == "--version") {
            a.version = true;
        } else if (s == "--ros-args") {
            ros_args = true;
        } else if (s == "--" && ros_args) {
            ros_args = false;
        } else if (ros_args && (s == "-p" || s == "--param")) {
            auto [k, v] = assignment(s, next);
            params.emplace_back(k, parsedText(k, v));
            ++i;
        } else if (ros_args && (s == "-r" || s == "--remap")) {
            remaps.push_back(assignment(s, next));
            ++i;
        } else if (ros_args && s == "--params-file") {
            if (!next) throw ConfigError(s, "needs a file");
            for (auto& p : paramsFile(next)) params.push_back(std::move(p));
            ++i;
        } else if (ros_args && s == "--log-level") {
            ++i;  // accepted: the node logs what matters whatever the level
        } else {
            throw ConfigError(s, ros_args ? "is not a --ros-args option (-p, -r, --params-file)"
                                          : "is not an option (kfd_ros2 --help)");
        }
    }
    if (!a.help && !a.version) a.config = ros2Config(params, remaps);
    return a;
}

}  // namespace kfd::ros2
