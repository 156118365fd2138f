#include "kfd/mrpt/config.h"

#include <mrpt/config/CConfigFile.h>
#include <mrpt/containers/yaml.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <map>
#include <sstream>

namespace kfd {
namespace {

std::string trim(const std::string& s) {
    const auto b = s.find_first_not_of(" \t\r\n");
    if (b == std::string::npos) return {};
    const auto e = s.find_last_not_of(" \t\r\n");
    return s.substr(b, e - b + 1);
}

std::string formatDouble(double v) {
    char buf[64];
    std::snprintf(buf, sizeof(buf), "%.10g", v);
    return buf;
}

double parseNumber(const std::string& key, const std::string& text) {
    const std::string t = trim(text);
    std::size_t pos = 0;
    double v = 0;
    try {
        v = std::stod(t, &pos);
    } catch (const std::exception&) {
        throw ConfigError(key, "'" + t + "' is not a number");
    }
    if (pos != t.size()) throw ConfigError(key, "'" + t + "' is not a number");
    if (!std::isfinite(v)) throw ConfigError(key, "'" + t + "' is not finite");
    return v;
}

// A key: how to parse and range-check it, and how to print it back.
struct Key {
    ConfigKeyInfo info;
    std::function<void(Pipeline::Params&, const std::string&)> set;
    std::function<std::string(const Pipeline::Params&)> get;
};

// Real value in [lo, hi] (or (lo, hi] when lo_open).
Key real(const std::string& name, const std::string& help, double lo, double hi, bool lo_open,
         double& (*field)(Pipeline::Params&)) {
    const std::string range =
        std::string(lo_open ? "(" : "[") + formatDouble(lo) + ", " + formatDouble(hi) + "]";
    return Key{{name, help, range},
               [=](Pipeline::Params& p, const std::string& text) {
                   const double v = parseNumber(name, text);
                   if ((lo_open ? v <= lo : v < lo) || v > hi)
                       throw ConfigError(name, formatDouble(v) + " is out of range " + range);
                   field(p) = v;
               },
               [=](const Pipeline::Params& p) {
                   return formatDouble(field(const_cast<Pipeline::Params&>(p)));
               }};
}

Key integer(const std::string& name, const std::string& help, double lo, double hi,
            std::size_t& (*field)(Pipeline::Params&)) {
    const std::string range = "[" + formatDouble(lo) + ", " + formatDouble(hi) + "], integer";
    return Key{{name, help, range},
               [=](Pipeline::Params& p, const std::string& text) {
                   const double v = parseNumber(name, text);
                   if (v != std::floor(v))
                       throw ConfigError(name, trim(text) + " is not an integer");
                   if (v < lo || v > hi)
                       throw ConfigError(name, formatDouble(v) + " is out of range " + range);
                   field(p) = static_cast<std::size_t>(v);
               },
               [=](const Pipeline::Params& p) {
                   return std::to_string(field(const_cast<Pipeline::Params&>(p)));
               }};
}

std::vector<Key> buildKeys() {
    using P = Pipeline::Params;
    std::vector<Key> k;
    k.push_back(Key{{"pipeline", "stages in order, comma separated",
                     "distance, keyframe, denoise, motion, dbscan, radius, sor"},
                    [](P& p, const std::string& text) {
                        std::vector<std::string> stages;
                        std::stringstream ss(text);
                        std::string item;
                        while (std::getline(ss, item, ',')) {
                            item = trim(item);
                            if (item.empty()) continue;
                            if (item != "distance" && item != "keyframe" && item != "denoise" &&
                                item != "motion" && item != "dbscan" && item != "radius" &&
                                item != "sor")
                                throw ConfigError("pipeline", "unknown stage '" + item +
                                                                  "' (known: distance, keyframe, "
                                                                  "denoise, motion, dbscan, "
                                                                  "radius, sor)");
                            for (const auto& s : stages)
                                if (s == item)
                                    throw ConfigError("pipeline", "stage '" + item + "' repeated");
                            stages.push_back(item);
                        }
                        p.stages = stages;
                    },
                    [](const P& p) {
                        std::string s;
                        for (const auto& st : p.stages) s += (s.empty() ? "" : ", ") + st;
                        return s;
                    }});
    // Algorithm 1
    k.push_back(real("min_range", "Algorithm 1: shortest usable range (m)", 0, 1000, false,
                     [](P& p) -> double& { return p.distance.min_range; }));
    k.push_back(real("max_range", "Algorithm 1: longest usable range (m)", 0, 1000, true,
                     [](P& p) -> double& { return p.distance.max_range; }));
    // Keyframe extraction
    k.push_back(integer("bins", "Sec. 3.1.2: histogram columns n", 2, 4096,
                        [](P& p) -> std::size_t& { return p.keyframe.bins; }));
    k.push_back(integer("window", "Sec. 3.1.4: sliding window m (keyframes compared)", 1, 1024,
                        [](P& p) -> std::size_t& { return p.keyframe.window; }));
    k.push_back(real("p_pair", "Formula 3: pairwise similarity threshold; P_threshold = P_pair^m",
                     0, 1, true, [](P& p) -> double& { return p.keyframe.p_pair; }));
    k.push_back(integer("max_consecutive_drops", "guard: force a keyframe after K drops (0 = off)",
                        0, 1e9,
                        [](P& p) -> std::size_t& { return p.keyframe.max_consecutive_drops; }));
    k.push_back(real("max_interval_s", "guard: force a keyframe after T seconds (0 = off)", 0, 1e9,
                     false, [](P& p) -> double& { return p.keyframe.max_interval_s; }));
    k.push_back(real("max_translation_m",
                     "guard: force a keyframe after D metres of odometry (0 = off)", 0, 1e6, false,
                     [](P& p) -> double& { return p.keyframe.max_translation_m; }));
    k.push_back(real("max_rotation_deg",
                     "guard: force a keyframe after A degrees of odometry turn (0 = off)", 0, 360,
                     false, [](P& p) -> double& { return p.keyframe.max_rotation_deg; }));
    // Denoise
    k.push_back(Key{{"variant", "denoiser: reference (the paper) or range_aware (kfd's)",
                     "reference, range_aware"},
                    [](P& p, const std::string& text) {
                        try {
                            p.denoise.variant = parseDenoiseVariant(trim(text));
                        } catch (const std::invalid_argument& e) {
                            throw ConfigError("variant", e.what());
                        }
                    },
                    [](const P& p) { return std::string(toString(p.denoise.variant)); }});
    k.push_back(integer("rings", "Sec. 3.2.1: equal-area rings t", 1, 254,
                        [](P& p) -> std::size_t& { return p.denoise.rings; }));
    k.push_back(real("ring_r_max", "Formulas 6-8: outer ring radius (m, 0 = farthest point)", 0,
                     1000, false, [](P& p) -> double& { return p.denoise.ring_r_max; }));
    k.push_back(real("angle_gap_factor",
                     "Sec. 3.2.2: theta_threshold in multiples of the angular resolution", 0, 1e4,
                     true, [](P& p) -> double& { return p.denoise.angle_gap_factor; }));
    k.push_back(real("merge_distance_m",
                     "Formula 10: d_threshold (m, 0 = chord of theta_threshold at the boundary)", 0,
                     1000, false, [](P& p) -> double& { return p.denoise.merge_distance_m; }));
    k.push_back(integer("m_threshold", "Sec. 3.2.4: clusters with fewer points are noise", 1, 1e6,
                        [](P& p) -> std::size_t& { return p.denoise.m_threshold; }));
    k.push_back(real("jump_lambda_deg", "range_aware: breakpoint incidence limit lambda (deg)", 0,
                     89.9, true, [](P& p) -> double& { return p.denoise.jump_lambda_deg; }));
    k.push_back(real("jump_sigma_m", "range_aware: sensor range noise sigma (m)", 0, 10, false,
                     [](P& p) -> double& { return p.denoise.jump_sigma_m; }));
    k.push_back(real("min_object_size_m",
                     "range_aware: object width that needs m_threshold points (m)", 0, 100, false,
                     [](P& p) -> double& { return p.denoise.min_object_size_m; }));
    k.push_back(integer("min_points_floor", "range_aware: fewest points a kept cluster may have", 1,
                        1e6, [](P& p) -> std::size_t& { return p.denoise.min_points_floor; }));
    // Baselines
    k.push_back(real("motion_distance_m", "motion stage: keep after D metres of odometry (0 = off)",
                     0, 1e6, false, [](P& p) -> double& { return p.motion.max_distance_m; }));
    k.push_back(real("motion_angle_deg", "motion stage: keep after A degrees of odometry (0 = off)",
                     0, 360, false, [](P& p) -> double& { return p.motion.max_angle_deg; }));
    k.push_back(real("motion_interval_s", "motion stage: keep after T seconds (0 = off)", 0, 1e9,
                     false, [](P& p) -> double& { return p.motion.max_interval_s; }));
    k.push_back(real("dbscan_eps_m", "dbscan stage: neighbourhood radius Eps (m)", 0, 100, true,
                     [](P& p) -> double& { return p.dbscan.eps_m; }));
    k.push_back(integer("dbscan_min_pts", "dbscan stage: minPts (the point itself included)", 1,
                        1e6, [](P& p) -> std::size_t& { return p.dbscan.min_pts; }));
    k.push_back(real("radius_m", "radius stage: neighbourhood radius (m)", 0, 100, true,
                     [](P& p) -> double& { return p.radius.radius_m; }));
    k.push_back(integer("radius_min_neighbors",
                        "radius stage: other points needed within radius_m (points)", 1, 1e6,
                        [](P& p) -> std::size_t& { return p.radius.min_neighbors; }));
    k.push_back(integer("sor_k", "sor stage: nearest neighbours per point (points)", 1, 1000,
                        [](P& p) -> std::size_t& { return p.sor.k; }));
    k.push_back(real("sor_std_mul",
                     "sor stage: noise above mean + sor_std_mul x stddev of the mean neighbour "
                     "distance (standard deviations)",
                     0, 100, false, [](P& p) -> double& { return p.sor.std_mul; }));
    return k;
}

const std::vector<Key>& keys() {
    static const std::vector<Key> k = buildKeys();
    return k;
}

const Key* findKey(const std::string& name) {
    for (const auto& k : keys())
        if (k.info.name == name) return &k;
    return nullptr;
}

std::string knownKeyList() {
    std::string s;
    for (const auto& k : keys()) s += (s.empty() ? "" : ", ") + k.info.name;
    return s;
}

// Applies a key=value pair; then re-validates the whole parameter set.
void apply(Pipeline::Params& p, const std::string& key, const std::string& value) {
    const Key* k = findKey(key);
    if (!k) throw ConfigError(key, "unknown key (known keys: " + knownKeyList() + ")");
    k->set(p, value);
}

void validate(const Pipeline::Params& p) {
    if (p.distance.max_range <= p.distance.min_range)
        throw ConfigError("max_range", "must be greater than min_range");
    try {
        Pipeline check(p);  // every stage validates its own parameters
    } catch (const std::invalid_argument& e) {
        throw ConfigError("", std::string("invalid configuration: ") + e.what());
    }
}

std::string scalarText(const mrpt::containers::yaml& node, const std::string& key) {
    if (node.isSequence()) {
        std::string s;
        for (const auto& item : node.asSequence()) {
            const mrpt::containers::yaml y(item);
            s += (s.empty() ? "" : ",") + scalarText(y, key);
        }
        return s;
    }
    if (!node.isScalar()) throw ConfigError(key, "expected a value or a list of values");
    try {
        return node.as<std::string>();
    } catch (const std::exception&) {
    }
    try {
        return formatDouble(node.as<double>());
    } catch (const std::exception&) {
    }
    try {
        return node.as<bool>() ? "1" : "0";
    } catch (const std::exception&) {
    }
    throw ConfigError(key, "cannot read the value");
}

}  // namespace

const std::vector<ConfigKeyInfo>& configKeys() {
    static const std::vector<ConfigKeyInfo> infos = [] {
        std::vector<ConfigKeyInfo> v;
        for (const auto& k : keys()) v.push_back(k.info);
        return v;
    }();
    return infos;
}

Pipeline::Params loadIni(const mrpt::config::CConfigFileBase& cfg, const std::string& section) {
    if (!cfg.sectionExists(section))
        throw ConfigError("", "no [" + section + "] section in the configuration");
    std::vector<std::string> names;
    cfg.getAllKeys(section, names);
    Pipeline::Params p;
    for (const auto& name : names) apply(p, name, cfg.read_string(section, name, ""));
    validate(p);
    return p;
}

Pipeline::Params loadYaml(const mrpt::containers::yaml& doc) {
    if (!doc.isMap()) throw ConfigError("", "the YAML document must be a map of kfd keys");
    const mrpt::containers::yaml root = doc.has("kfd") ? doc["kfd"] : doc;
    if (!root.isMap()) throw ConfigError("kfd", "must be a map of kfd keys");
    Pipeline::Params p;
    for (const auto& kv : root.asMap()) {
        const std::string name = std::string(kv.first.internalAsStr());
        apply(p, name, scalarText(mrpt::containers::yaml(kv.second), name));
    }
    validate(p);
    return p;
}

Pipeline::Params loadConfigFile(const std::string& path, const std::string& section) {
    namespace fs = std::filesystem;
    std::error_code ec;
    if (!fs::is_regular_file(path, ec))
        throw ConfigError("", "configuration file not found: " + path);
    std::string ext = fs::path(path).extension().string();
    for (auto& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (ext == ".yaml" || ext == ".yml") {
        mrpt::containers::yaml doc;
        try {
            doc = mrpt::containers::yaml::FromFile(path);
        } catch (const std::exception& e) {
            throw ConfigError("", "cannot parse YAML file " + path + ": " + e.what());
        }
        return loadYaml(doc);
    }
    if (ext != ".ini" && ext != ".cfg")
        throw ConfigError("", "unknown configuration format '" + ext + "' (use .ini or .yaml)");
    mrpt::config::CConfigFile cfg(path);
    return loadIni(cfg, section);
}

std::string toIni(const Pipeline::Params& p, const std::string& section) {
    std::string s = "[" + section + "]\n";
    for (const auto& k : keys()) s += k.info.name + " = " + k.get(p) + "\n";
    return s;
}

}  // namespace kfd
