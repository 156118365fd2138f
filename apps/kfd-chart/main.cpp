// kfd-chart: a grouped bar chart (with error bars) from a CSV, as PNG, without a display.
#include <cstdio>
#include <string>

#include "kfd/render/bar_chart.h"

int main(int argc, char** argv) {
    std::string csv, out, title, ylabel;
    bool log_y = false;
    int width = 1000, height = 500;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "-h" || a == "--help") {
            std::puts(
                "Usage: kfd-chart CSV -o OUT.png [--title T] [--ylabel L] [--log] [--size W H]\n"
                "CSV: a header line, then 'group,series,value[,error]' rows.");
            return 0;
        }
        if (a == "--log") {
            log_y = true;
            continue;
        }
        if (a == "--size") {
            if (i + 2 >= argc) return 2;
            width = std::atoi(argv[++i]);
            height = std::atoi(argv[++i]);
            continue;
        }
        if (a == "-o" || a == "--title" || a == "--ylabel") {
            if (i + 1 >= argc) {
                std::fprintf(stderr, "kfd-chart: %s needs a value\n", a.c_str());
                return 2;
            }
            (a == "-o" ? out : a == "--title" ? title : ylabel) = argv[++i];
            continue;
        }
        if (!a.empty() && a[0] == '-') {
            std::fprintf(stderr, "kfd-chart: unknown option '%s'\n", a.c_str());
            return 2;
        }
        csv = a;
    }
    if (csv.empty() || out.empty()) {
        std::fprintf(stderr, "kfd-chart: give CSV and -o OUT.png (see --help)\n");
        return 2;
    }
    try {
        auto c = kfd::readBarChartCsv(csv);
        c.title = title;
        c.y_label = ylabel;
        c.log_y = log_y;
        c.width = width;
        c.height = height;
        if (!c.render().saveToFile(out)) throw std::runtime_error("cannot write " + out);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "kfd-chart: %s\n", e.what());
        return 1;
    }
    return 0;
}
