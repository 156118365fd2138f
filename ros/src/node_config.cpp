#include "kfd/ros1/node_config.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <sstream>

#include "kfd/mrpt/config.h"
#include "kfd/mrpt/default_stages.h"
#include "kfd/stages/track_stage.h"

namespace kfd::ros1 {

namespace {

using XmlRpc::XmlRpcValue;

const char* typeName(XmlRpcValue::Type t) {
    switch (t) {
        case XmlRpcValue::TypeBoolean:
            return "a bool";
        case XmlRpcValue::TypeInt:
            return "an int";
        case XmlRpcValue::TypeDouble:
            return "a double";
        case XmlRpcValue::TypeString:
            return "a string";
        case XmlRpcValue::TypeArray:
            return "a list";
        case XmlRpcValue::TypeStruct:
            return "a map";
        default:
            return "a value of another type";
    }
}

// A scalar parameter as text (a double as %.17g so that no digit is lost).
std::string scalarText(const std::string& key, XmlRpcValue v) {
    switch (v.getType()) {
        case XmlRpcValue::TypeBoolean:
            return bool(v) ? "true" : "false";
        case XmlRpcValue::TypeInt:
            return std::to_string(int(v));
        case XmlRpcValue::TypeDouble: {
            std::ostringstream s;
            s.precision(17);
            s << double(v);
            return s.str();
        }
        case XmlRpcValue::TypeString:
            return std::string(v);
        default:
            throw ConfigError(
                key, std::string("is ") + typeName(v.getType()) + ", not a number, bool or string");
    }
}

// A kfd key's value: a scalar, or a list of scalars joined with commas (`pipeline`).
std::string keyText(const std::string& key, XmlRpcValue v) {
    if (v.getType() != XmlRpcValue::TypeArray) return scalarText(key, v);
    std::string text;
    for (int i = 0; i < v.size(); ++i) text += (i ? "," : "") + scalarText(key, v[i]);
    return text;
}

std::string stringParam(const std::string& key, XmlRpcValue v) {
    if (v.getType() != XmlRpcValue::TypeString)
        throw ConfigError(key, std::string("is ") + typeName(v.getType()) + ", not a string");
    return std::string(v);
}

// A tf2 frame id: not empty, no leading '/' (tf2 refuses it in every lookup), no white space.
std::string frameParam(const std::string& key, XmlRpcValue v) {
    const std::string f = stringParam(key, v);
    if (f.empty()) throw ConfigError(key, "is empty: a tf frame id is needed (e.g. odom)");
    if (f[0] == '/')
        throw ConfigError(key, "'" + f + "': tf2 frame ids do not start with '/' (use '" +
                                   f.substr(std::min(f.find_first_not_of('/'), f.size())) + "')");
    for (const char ch : f)
        if (std::isspace(static_cast<unsigned char>(ch)) || ch == '\0')
            throw ConfigError(key, "'" + f + "' holds white space: not a tf frame id");
    return f;
}

int intParam(const std::string& key, XmlRpcValue v, int lo, int hi) {
    if (v.getType() != XmlRpcValue::TypeInt)
        throw ConfigError(key, std::string("is ") + typeName(v.getType()) + ", not an int");
    const int n = int(v);
    if (n < lo || n > hi)
        throw ConfigError(key, std::to_string(n) + " is outside [" + std::to_string(lo) + ", " +
                                   std::to_string(hi) + "]");
    return n;
}

double secondsParam(const std::string& key, XmlRpcValue v, double lo, double hi) {
    double d = 0.0;
    if (v.getType() == XmlRpcValue::TypeDouble)
        d = double(v);
    else if (v.getType() == XmlRpcValue::TypeInt)
        d = int(v);
    else
        throw ConfigError(key, std::string("is ") + typeName(v.getType()) + ", not a number");
    if (!std::isfinite(d) || d < lo || d > hi) {
        std::ostringstream s;
        s << d << " is outside [" << lo << ", " << hi << "] s";
        throw ConfigError(key, s.str());
    }
    return d;
}

// ~track_tf publishes odom_frame -> base_frame from the track: it needs the track stage, and
// the node must not read the odometry it writes.
void checkTrackTf(const NodeConfig& c) {
    if (!c.track_tf) return;
    if (!c.pipeline.lists(TrackStage::kName))
        throw ConfigError("track_tf", "true, but the pipeline does not list the track stage");
    if (c.odometry == NodeConfig::Odometry::Tf)
        throw ConfigError("track_tf",
                          "true with ~odom: tf would read back the transform it publishes (" +
                              c.odom_frame + " -> " + c.base_frame + "); set ~odom: topic or none");
}

}  // namespace

bool isNodeParameter(const std::string& name) {
    for (const char* n : {"config", "odom", "odom_frame", "base_frame", "tf_wait", "removed_as",
                          "reset_jump", "queue_size", "max_sensors", "track_topic", "track_tf"})
        if (name == n) return true;
    return false;
}

NodeConfig nodeConfig(const std::map<std::string, XmlRpc::XmlRpcValue>& params) {
    NodeConfig c;
    if (const auto it = params.find("config"); it != params.end())
        c.config_path = stringParam("config", it->second);
    c.pipeline =
        c.config_path.empty() ? kfdDefaults() : loadConfigFile(c.config_path, "KFD", &c.notes);
    ConfigValues kfd_keys;  // in kfd's order, below
    for (const auto& [key, value] : params) {
        if (key == "odom") {
            const std::string s = stringParam(key, value);
            if (s == "tf")
                c.odometry = NodeConfig::Odometry::Tf;
            else if (s == "topic")
                c.odometry = NodeConfig::Odometry::Topic;
            else if (s == "none")
                c.odometry = NodeConfig::Odometry::None;
            else
                throw ConfigError(key, "'" + s + "' is not tf, topic or none");
        } else if (key == "odom_frame") {
            c.odom_frame = frameParam(key, value);
        } else if (key == "base_frame") {
            c.base_frame = frameParam(key, value);
        } else if (key == "tf_wait") {
            c.tf_wait = secondsParam(key, value, 0.0, 10.0);
        } else if (key == "reset_jump") {
            c.reset_jump = secondsParam(key, value, 0.0, 1e9);
        } else if (key == "queue_size") {
            c.queue_size = intParam(key, value, 1, 1000);
        } else if (key == "max_sensors") {
            c.max_sensors = intParam(key, value, 1, 100000);
        } else if (key == "track_topic") {
            c.track_topic = stringParam(key, value);
        } else if (key == "track_tf") {
            if (value.getType() != XmlRpc::XmlRpcValue::TypeBoolean)
                throw ConfigError(key,
                                  std::string("is ") + typeName(value.getType()) + ", not a bool");
            c.track_tf = bool(XmlRpc::XmlRpcValue(value));
        } else if (key == "removed_as") {
            try {
                c.removed = parseRemovedMark(stringParam(key, value));
            } catch (const ConfigError&) {
                throw;
            } catch (const Error& e) {
                throw ConfigError(key, e.what());
            }
        } else if (key != "config" && value.getType() == XmlRpc::XmlRpcValue::TypeStruct) {
            ConfigValues::Section stage{key, {}};  // ~<stage>/<key>: that stage's keys
            for (auto& [name, v] : value) stage.keys.emplace_back(name, keyText(name, v));
            kfd_keys.sections.push_back(std::move(stage));
        } else if (key != "config") {
            kfd_keys.keys.emplace_back(key, keyText(key, value));
        }
    }
    applyConfig(c.pipeline, kfd_keys, defaultStageRegistry(),
                ConfigSyntax{ConfigSyntax::RosParams, "KFD"}, &c.notes);
    validateConfig(c.pipeline, defaultStageRegistry());
    checkTrackTf(c);
    return c;
}

}  // namespace kfd::ros1
