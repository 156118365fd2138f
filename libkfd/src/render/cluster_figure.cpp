#include "kfd/render/cluster_figure.h"

#include <GL/osmesa.h>
#include <mrpt/opengl/CFBORender.h>
#include <mrpt/opengl/CGridPlaneXY.h>
#include <mrpt/opengl/COpenGLScene.h>
#include <mrpt/opengl/CPointCloudColoured.h>
#include <mrpt/opengl/CSetOfLines.h>

#include <cmath>
#include <string>
#include <vector>

namespace kfd {

struct ClusterFigure::Impl {
    OSMesaContext ctx = nullptr;
    std::vector<unsigned char> buffer;
    std::unique_ptr<mrpt::opengl::CFBORender> fbo;
};

ClusterFigure::ClusterFigure(const ClusterFigureOptions& opts)
    : impl_(std::make_unique<Impl>()), opts_(opts) {
    if (opts.width < 16 || opts.height < 16) throw RenderError("figure size too small");
    if (opts.width > 10000 || opts.height > 10000 || double(opts.width) * opts.height > 40.0e6)
        throw RenderError("figure size too large: " + std::to_string(opts.width) + " x " +
                          std::to_string(opts.height) +
                          " px (at most 10000 a side and 40 million pixels)");
    // OSMesa core-profile context (see ../shared/notes/platform.md), then MRPT's FBO renderer.
    const int attribs[] = {OSMESA_FORMAT,
                           OSMESA_RGBA,
                           OSMESA_DEPTH_BITS,
                           24,
                           OSMESA_PROFILE,
                           OSMESA_CORE_PROFILE,
                           OSMESA_CONTEXT_MAJOR_VERSION,
                           3,
                           OSMESA_CONTEXT_MINOR_VERSION,
                           3,
                           0};
    impl_->ctx = OSMesaCreateContextAttribs(attribs, nullptr);
    if (!impl_->ctx) throw RenderError("cannot create an OSMesa OpenGL 3.3 context");
    impl_->buffer.resize(static_cast<std::size_t>(opts.width) * opts.height * 4);
    if (!OSMesaMakeCurrent(impl_->ctx, impl_->buffer.data(), GL_UNSIGNED_BYTE, opts.width,
                           opts.height))
        throw RenderError("cannot make the OSMesa context current");
    mrpt::opengl::CFBORender::Parameters p(opts.width, opts.height);
    p.create_EGL_context = false;
    impl_->fbo = std::make_unique<mrpt::opengl::CFBORender>(p);
}

ClusterFigure::~ClusterFigure() {
    impl_->fbo.reset();
    if (impl_->ctx) OSMesaDestroyContext(impl_->ctx);
}

std::array<std::uint8_t, 3> ClusterFigure::colourOf(std::int32_t label, bool noise) {
    if (noise) return {230, 20, 20};
    static const std::array<std::uint8_t, 3> palette[] = {
        {31, 119, 180}, {44, 160, 44},   {148, 103, 189}, {140, 86, 75}, {23, 190, 207},
        {188, 189, 34}, {227, 119, 194}, {255, 127, 14},  {80, 80, 80},  {0, 90, 50}};
    return palette[static_cast<std::size_t>(label < 0 ? 0 : label) % 10];
}

std::pair<int, int> ClusterFigure::pixelOf(double x, double y) const {
    // Orthographic top view: the visible height is 2 * half_extent_ metres.
    const double s = 0.5 * opts_.height / half_extent_;
    return {static_cast<int>(std::lround(0.5 * opts_.width + (x - centre_x_) * s)),
            static_cast<int>(std::lround(0.5 * opts_.height - (y - centre_y_) * s))};
}

namespace {

// The bounding box (m) of what a figure fitted to the scan shows: the returns and the sensor.
struct Box {
    double min_x = 0.0, max_x = 0.0, min_y = 0.0, max_y = 0.0;  // starts at the sensor
    void add(double x, double y) {
        min_x = std::min(min_x, x);
        max_x = std::max(max_x, x);
        min_y = std::min(min_y, y);
        max_y = std::max(max_y, y);
    }
};

// The clustered points (each cluster its colour) and the noise points (red, larger, above),
// and the box they span with the sensor.
Box scanPoints(const Scan& scan, const Clusters& c, mrpt::opengl::CPointCloudColoured& pts,
               mrpt::opengl::CPointCloudColoured& noise) {
    Box box;
    for (std::size_t i = 0; i < scan.size() && i < c.label.size(); ++i) {
        if (!scan.valid[i] || c.label[i] < 0) continue;
        const double a = scan.geometry.angle(i), r = scan.range[i];
        const float x = static_cast<float>(r * std::cos(a)),
                    y = static_cast<float>(r * std::sin(a));
        const bool is_noise = c.noise[static_cast<std::size_t>(c.label[i])] != 0;
        const auto col = ClusterFigure::colourOf(c.label[i], is_noise);
        (is_noise ? noise : pts)
            .insertPoint({x, y, is_noise ? 0.02f : 0.0f, col[0], col[1], col[2]});
        box.add(x, y);
    }
    return box;
}

// Formulas 6-8's ring boundaries r_i = sqrt(i) r_max / sqrt(t), as circles of 180 segments.
mrpt::opengl::CSetOfLines::Ptr ringLines(std::size_t rings, double r_max) {
    auto lines = mrpt::opengl::CSetOfLines::Create();
    lines->setColor_u8(200, 200, 235);
    for (std::size_t i = 1; i <= rings; ++i) {
        const double ri = std::sqrt(double(i) / double(rings)) * r_max;
        for (int k = 0; k < 180; ++k) {
            const double a0 = 2 * kPi * k / 180, a1 = 2 * kPi * (k + 1) / 180;
            lines->appendLine(ri * std::cos(a0), ri * std::sin(a0), -0.005, ri * std::cos(a1),
                              ri * std::sin(a1), -0.005);
        }
    }
    return lines;
}

// The sensor at the origin (an arrow) and a 1 m scale bar at the bottom left of the view
// centred on (cx, cy).
mrpt::opengl::CSetOfLines::Ptr markLines(double he, double half_extent, double cx, double cy) {
    auto marks = mrpt::opengl::CSetOfLines::Create();
    marks->setColor_u8(0, 0, 0);
    marks->setLineWidth(2.0f);
    marks->appendLine(-0.15, -0.1, 0.01, 0.25, 0.0, 0.01);
    marks->appendLine(0.25, 0.0, 0.01, -0.15, 0.1, 0.01);
    marks->appendLine(-0.15, 0.1, 0.01, -0.15, -0.1, 0.01);
    const double bx = cx - he * 0.9, by = cy - half_extent * 0.9;
    marks->appendLine(bx, by, 0.01, bx + 1.0, by, 0.01);
    marks->appendLine(bx, by - 0.05, 0.01, bx, by + 0.05, 0.01);
    marks->appendLine(bx + 1.0, by - 0.05, 0.01, bx + 1.0, by + 0.05, 0.01);
    return marks;
}

// The title and the legend, in a bitmap font on the rendered image.
void drawLegend(mrpt::img::CImage& img, const std::string& title, bool rings) {
    const mrpt::img::TColor black(0, 0, 0), red(230, 20, 20);
    img.selectTextFont("6x13");
    int y = 6;
    if (!title.empty()) {
        img.textOut(8, y, title, black);
        y += 16;
    }
    img.textOut(8, y, "clusters: one colour each", black);
    img.filledRectangle(8, y + 18, 16, y + 26, red);
    img.textOut(22, y + 16, "removed as noise", black);
    img.textOut(8, y + 32, "1 m grid; bar (bottom left) = 1 m; arrow = sensor", black);
    if (rings) img.textOut(8, y + 48, "rings: equal-area boundaries", black);
}

}  // namespace

mrpt::img::CImage ClusterFigure::render(const Scan& scan, const Clusters& c) {
    using namespace mrpt::opengl;
    if (!OSMesaMakeCurrent(impl_->ctx, impl_->buffer.data(), GL_UNSIGNED_BYTE, opts_.width,
                           opts_.height))
        throw RenderError("cannot make the OSMesa context current");
    COpenGLScene scene;
    auto pts = CPointCloudColoured::Create();
    auto noise = CPointCloudColoured::Create();
    pts->setPointSize(opts_.point_size);
    noise->setPointSize(2.0f * opts_.point_size);
    const Box box = scanPoints(scan, c, *pts, *noise);
    const double aspect = double(opts_.width) / opts_.height;
    if (opts_.half_extent_m > 0) {
        half_extent_ = opts_.half_extent_m;
        centre_x_ = centre_y_ = 0.0;
    } else {  // the box with a 5 % margin, at least 1 m high, below the legend's rows
        const int rows = 3 + (opts_.title.empty() ? 0 : 1) + (opts_.ring_r_max > 0 ? 1 : 0);
        const double band = std::min(0.5, (16.0 * rows + 8.0) / opts_.height);
        centre_x_ = 0.5 * (box.min_x + box.max_x);
        half_extent_ = std::max(
            {0.5, 0.525 * (box.max_y - box.min_y), 0.525 * (box.max_x - box.min_x) / aspect});
        half_extent_ /= 1.0 - band;
        centre_y_ = 0.5 * (box.min_y + box.max_y) + band * half_extent_;
    }
    const double he = half_extent_ * aspect;  // half the visible width
    auto grid =
        CGridPlaneXY::Create(static_cast<float>(std::floor(centre_x_ - he)),
                             static_cast<float>(std::ceil(centre_x_ + he)),
                             static_cast<float>(std::floor(centre_y_ - half_extent_)),
                             static_cast<float>(std::ceil(centre_y_ + half_extent_)), -0.01f, 1.0f);
    grid->setColor_u8(220, 220, 220);
    scene.insert(grid);
    if (opts_.ring_r_max > 0 && opts_.rings > 0)
        scene.insert(ringLines(opts_.rings, opts_.ring_r_max));
    scene.insert(markLines(he, half_extent_, centre_x_, centre_y_));
    scene.insert(pts);
    scene.insert(noise);
    scene.getViewport()->setCustomBackgroundColor({1.0f, 1.0f, 1.0f, 1.0f});
    auto& cam = impl_->fbo->getCamera(scene);
    cam.setOrthogonal(true);
    cam.setAzimuthDegrees(-90.0f);
    cam.setElevationDegrees(90.0f);
    cam.setPointingAt(static_cast<float>(centre_x_), static_cast<float>(centre_y_), 0.0f);
    cam.setZoomDistance(static_cast<float>(4.0 * half_extent_));  // visible height = zoom / 2
    mrpt::img::CImage img;
    try {
        impl_->fbo->render_RGB(scene, img);
    } catch (const std::exception& e) {
        throw RenderError(std::string("rendering failed: ") + e.what());
    }
    drawLegend(img, opts_.title, opts_.ring_r_max > 0);
    return img;
}

}  // namespace kfd
