// kfd-chart: a grouped bar chart (with error bars) from a CSV, as PNG, without a display.
#include <string>
#include <vector>

#include "common/cli.h"
#include "kfd/io/png_output.h"
#include "kfd/os/cancel.h"
#include "kfd/plot/bar_chart.h"

int main(int argc, char** argv) {
    kfd::app::Cli cli("kfd-chart", "CSV -o OUT.png [--title T] [--ylabel L] [--log] [--size W H]",
                      "CSV: a header line, then 'group,series,value[,error]' rows.");
    std::string csv, out, title, ylabel;
    bool log_y = false;
    std::vector<int> size{1000, 500};
    cli.option("CSV", csv, "the bars")->type_name("FILE")->required();
    cli.option("-o", out, "output PNG")->type_name("OUT.png")->required();
    cli.option("--title", title, "chart title")->type_name("T");
    cli.option("--ylabel", ylabel, "y axis label")->type_name("L");
    cli.flag("--log", log_y, "logarithmic y axis");
    cli.option("--size", size,
               "image width and height in pixels (default 1000 500; 200 to\n10000 each, at most 40 "
               "million pixels)",
               2, 2)
        ->option_text("W H");
    cli.cancelOnSignal();  // outputs: stop cleanly on SIGINT/SIGTERM/SIGHUP
    return cli.run(argc, argv, [&] {
        kfd::app::checkOutputPaths({{"input CSV", csv}}, {{"output image", out}});
        auto c = kfd::readBarChartCsv(csv);
        c.title = title;
        c.y_label = ylabel;
        c.log_y = log_y;
        c.width = size[0];
        c.height = size[1];
        kfd::TempOutputFile tmp(out);  // written under a temporary name, renamed when complete
        kfd::writePng(c.render(), tmp.path(), out);  // every write checked (WriteError)
        kfd::throwIfCancelled();  // interrupted while drawing: nothing is moved into place
        tmp.commit();
    });
}
