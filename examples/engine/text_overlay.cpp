#include "text_overlay.hpp"

#include <crisp/effects.hpp>
#include <crisp/transform.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace engine {
namespace {

// The HUD: a panel at the top left of the window, in pixels.
constexpr float kHudX = 12.0f, kHudY = 12.0f, kHudWidth = 262.0f, kPadding = 12.0f;
constexpr float kTitleSize = 17.0f, kBodySize = 13.0f, kCounterSize = 12.0f, kRowSize = 12.0f, kLabelSize = 15.0f;
constexpr float kSpinnerSize = 14.0f, kSignSize = 24.0f;
constexpr float kRowHeight = 17.0f;
constexpr uint32_t kVisibleRows = 5;
// Rows glide up by a fraction of a pixel per frame: they never sit on whole pixels for long.
constexpr float kScrollPerFrame = 0.37f;
// Labels: the gap between a label's background and the point it marks, and the background's margin.
constexpr float kStem = 10.0f, kLabelMargin = 4.0f;
// The spinner turns this many degrees clockwise a frame (a turn in 240 frames), below the HUD.
constexpr double kSpinPerFrame = 1.5;
constexpr float kSpinnerGap = 10.0f;
// The text field: its height, widest width and the gap to the HUD and the window's edges.
constexpr float kFieldHeight = 30.0f, kFieldMaxWidth = 400.0f, kFieldGap = 12.0f;
// The sign's text spans this part of the cube face's width.
constexpr float kSignFill = 0.8f;
constexpr double kPi = 3.14159265358979323846;

// DrawOptions::id: each label and each row keeps its name from frame to frame.
constexpr uint64_t kLabelId = 1;
constexpr uint64_t kRowId = 100;
constexpr uint64_t kSpinnerId = 200;
constexpr uint64_t kSignId = 300;
constexpr uint64_t kFieldId = 400;
// Paint orders: each text its own range (the HUD's texts do not overlap, so any order would do).
constexpr uint32_t kCounterPaintOrder = 10000;
constexpr uint32_t kRowPaintOrder = 20000, kRowPaintOrders = 256;  // per row
constexpr uint32_t kSpinnerPaintOrder = 30000;
constexpr uint32_t kLabelPaintOrder = 40000;
constexpr uint32_t kSignPaintOrder = 50000;

// Text colours are sRGB (as crisp takes them); panel colours are linear (the scene target's).
constexpr std::array<float, 4> kWhite = {1.0f, 1.0f, 1.0f, 1.0f};
constexpr std::array<float, 4> kBodyColor = {0.80f, 0.84f, 0.90f, 1.0f};
constexpr std::array<float, 4> kCounterColor = {0.55f, 0.90f, 0.62f, 1.0f};
constexpr std::array<float, 4> kRowColor = {0.88f, 0.86f, 0.78f, 1.0f};
constexpr std::array<float, 4> kLabelColor = {0.94f, 0.95f, 0.97f, 1.0f};
constexpr std::array<float, 4> kHoverColor = {1.0f, 0.78f, 0.22f, 1.0f};
constexpr std::array<float, 4> kSpinnerColor = {0.98f, 0.72f, 0.86f, 1.0f};
constexpr std::array<float, 4> kSignColor = {0.55f, 0.93f, 1.0f, 1.0f};
constexpr std::array<float, 4> kHudPanel = {0.004f, 0.005f, 0.009f, 0.80f};
constexpr std::array<float, 4> kListPanel = {0.0f, 0.0f, 0.0f, 0.45f};
constexpr std::array<float, 4> kLabelPanel = {0.003f, 0.004f, 0.007f, 0.72f};
constexpr std::array<float, 4> kHoverPanel = {0.10f, 0.05f, 0.0f, 0.85f};
constexpr std::array<float, 4> kMarker = {0.9f, 0.9f, 0.9f, 0.9f};

constexpr const char* kParagraph =
    "The labels are laid out once and moved every frame by a draw option, at their depth from the "
    "camera; the one nearest the centre takes its hover colour the same way. crisp composites all "
    "text into the engine's HDR target before the blit to the swapchain.";
constexpr std::array<const char*, 10> kRows = {
    "01   Iron ore \xC3\x97 12",      "02   Copper wire \xC3\x97 3",  "03   Glass lens \xC3\x97 1",
    "04   Quartz crystal \xC3\x97 7", "05   Spring steel \xC3\x97 2", "06   Brass gear \xC3\x97 16",
    "07   Lamp oil \xC3\x97 4",       "08   Silk thread \xC3\x97 30", "09   Cedar plank \xC3\x97 9",
    "10   Tin plate \xC3\x97 5",
};

crisp::TextStyle style(float size, const std::array<float, 4>& color) {
    crisp::TextStyle out;
    out.size = size;
    std::copy(color.begin(), color.end(), out.color);
    out.depth = 0.0f;  // the HUD is nearest; labels take their depth as a draw option
    return out;
}

crisp::LayoutOptions at(float x, float y, uint32_t first_paint_order, float wrap_width = 0.0f) {
    crisp::LayoutOptions out;
    out.origin_x = x;
    out.origin_y = y;
    out.wrap_width = wrap_width;
    out.first_paint_order = first_paint_order;
    return out;
}

// Window pixels of a point through the view-projection; nullopt behind the eye.
std::optional<std::array<float, 2>> to_window(const Mat4& view_projection, Vec3 point, float width, float height) {
    const std::array<float, 4> clip = transform_point(view_projection, point);
    if (!(clip[3] > 0.0f)) return std::nullopt;
    return std::array<float, 2>{(clip[0] / clip[3] + 1.0f) * 0.5f * width, (clip[1] / clip[3] + 1.0f) * 0.5f * height};
}

std::array<float, 3> to_array(Vec3 v) {
    return {v.x, v.y, v.z};
}

}  // namespace

TextOverlay::TextOverlay(std::vector<crisp::Font> fonts, uint32_t caret_blink_ms) : fonts_(std::move(fonts)) {
    for (const crisp::Font& font : fonts_) font_chain_.push_back(&font);
    field_.emplace(font_chain_, layouter_, caret_blink_ms);
}

crisp::Result<std::unique_ptr<TextOverlay>> TextOverlay::create(const Device& device, std::vector<crisp::Font> fonts,
                                                                uint32_t caret_blink_ms) {
    std::unique_ptr<TextOverlay> self(new TextOverlay(std::move(fonts), caret_blink_ms));
    crisp::RendererCreateInfo renderer_info;
    renderer_info.instance = device.instance();
    renderer_info.instance_api_version = Device::kInstanceApiVersion;
    renderer_info.get_instance_proc_addr = vkGetInstanceProcAddr;  // volk's: crisp calls what the engine calls
    renderer_info.physical_device = device.physical_device();
    renderer_info.device = device.device();
    renderer_info.queue_family = device.queue_family();
    renderer_info.enabled_features = device.enabled_features();
    renderer_info.frames_in_flight = kFramesInFlight;
    renderer_info.atlas.width = 1024;  // a HUD and a few labels use a few percent of it
    renderer_info.atlas.height = 1024;
    crisp::Result<crisp::Renderer> renderer = crisp::Renderer::create(renderer_info);
    if (!renderer) return renderer.error();
    self->renderer_.emplace(std::move(*renderer));
    for (const crisp::Font& font : self->fonts_) {
        if (crisp::Status s = self->renderer_->add_font(font); !s) return s.error();
    }

    crisp::CompositorCreateInfo compositor_info;
    compositor_info.instance = device.instance();
    compositor_info.instance_api_version = Device::kInstanceApiVersion;
    compositor_info.get_instance_proc_addr = vkGetInstanceProcAddr;
    compositor_info.physical_device = device.physical_device();
    compositor_info.device = device.device();
    compositor_info.enabled_features = device.enabled_features();
    compositor_info.frames_in_flight = kFramesInFlight;
    crisp::Result<crisp::Compositor> compositor = crisp::Compositor::create(compositor_info);
    if (!compositor) return compositor.error();
    self->compositor_.emplace(std::move(*compositor));
    if (!self->compositor_->supports_target_format(kSceneColorFormat)) {
        return crisp::Error{crisp::ErrorCode::vulkan, "crisp's compositor cannot store to R16G16B16A16_SFLOAT here"};
    }
    if (crisp::Status s = self->lay_out_static(); !s) return s.error();
    return self;
}

crisp::Status TextOverlay::lay_out(std::string_view text, const crisp::TextStyle& text_style,
                                   const crisp::LayoutOptions& options, crisp::TextLayout& out) {
    return layouter_.layout(font_chain_, text, text_style, options, out);
}

// The HUD's text that never changes is laid out where it is drawn; the rows and labels, which
// move, at the origin: draw options place them each frame.
crisp::Status TextOverlay::lay_out_static() {
    const float x = kHudX + kPadding, wrap = kHudWidth - 2.0f * kPadding;
    const float ascender = fonts_.front().ascender();
    float y = kHudY + kPadding;
    // With an emoji font, the title ends in a colour glyph: its layers are drawn like any glyph.
    const std::string title =
        fonts_.size() > 1 ? "crisp in a small engine \xF0\x9F\x98\x80" : "crisp in a small engine";
    crisp::Status s = lay_out(title, style(kTitleSize, kWhite), at(x, y + ascender * kTitleSize, 0), title_);
    y = title_.y + title_.height + 4.0f;
    if (s) {
        // Spans over the one paragraph: its words about hovering in the hover colour, "HDR target"
        // underlined; shaped as one text, so kerning across the boundaries is kept.
        const std::string_view paragraph = kParagraph;
        crisp::TextStyle hover = style(kBodySize, kHoverColor);
        crisp::TextStyle underlined = style(kBodySize, kBodyColor);
        underlined.underline = true;
        const auto span_of = [&](std::string_view words, const crisp::TextStyle& span_style) {
            const auto begin = static_cast<uint32_t>(paragraph.find(words));
            return crisp::TextSpan{begin, begin + static_cast<uint32_t>(words.size()), span_style};
        };
        const crisp::TextSpan spans[] = {span_of("hover colour", hover), span_of("HDR target", underlined)};
        s = layouter_.layout(font_chain_, paragraph, style(kBodySize, kBodyColor), spans,
                             at(x, y + ascender * kBodySize, title_.next_paint_order, wrap), paragraph_);
    }
    y = paragraph_.y + paragraph_.height + 6.0f;
    counter_y_ = y + ascender * kCounterSize;
    y += 2.0f * fonts_.front().line_height() * kCounterSize + 6.0f;  // the counter's two lines
    list_box_ = {x, std::round(y), wrap, kVisibleRows * kRowHeight, kListPanel};
    list_clip_ = {{static_cast<int32_t>(list_box_.x), static_cast<int32_t>(list_box_.y)},
                  {static_cast<uint32_t>(list_box_.width), static_cast<uint32_t>(list_box_.height)}};
    hud_ = {kHudX, kHudY, kHudWidth, list_box_.y + list_box_.height + kPadding - kHudY, kHudPanel};
    rows_.resize(kRows.size());
    for (uint32_t i = 0; s && i < kRows.size(); ++i) {
        s = lay_out(kRows[i], style(kRowSize, kRowColor), at(0, 0, kRowPaintOrder + i * kRowPaintOrders), rows_[i]);
    }
    for (uint32_t i = 0; s && i < kShapeCount; ++i) {
        s = lay_out(kShapeNames[i], style(kLabelSize, kLabelColor), at(0, 0, kLabelPaintOrder + i * 64), labels_[i]);
    }
    if (s) s = lay_out("rotating", style(kSpinnerSize, kSpinnerColor), at(0, 0, kSpinnerPaintOrder), spinner_);
    const float side = std::ceil(std::hypot(spinner_.width, spinner_.height)) + 2.0f * kLabelMargin;
    spinner_panel_ = {std::round(kHudX + (kHudWidth - side) / 2.0f), hud_.y + hud_.height + kSpinnerGap, side, side,
                      kLabelPanel};
    if (s) s = lay_out("CRISP", style(kSignSize, kSignColor), at(0, 0, kSignPaintOrder), sign_);
    if (s) s = field_->set_text(kFieldText);
    return s;
}

const OverlayFrame& TextOverlay::draw(uint64_t frame, VkExtent2D extent, const SceneState& scene) {
    renderer_->begin_frame();
    frame_.panels.assign({hud_, list_box_, spinner_panel_});
    frame_.boxes.clear();
    draw_hud(frame, extent);
    draw_list(frame);
    draw_spinner(frame);
    draw_labels(extent, scene);
    draw_sign(extent, scene);
    draw_field(extent);
    return frame_;
}

TextBox TextOverlay::box_of(const char* name, const crisp::TextLayout& layout, float dx, float dy) const {
    TextBox box;
    box.name = name;
    box.x = layout.x + dx;
    box.y = layout.y + dy;
    box.width = layout.width;
    box.height = layout.height;
    return box;
}

void TextOverlay::draw_hud(uint64_t frame, VkExtent2D extent) {
    // The title with an outline and a drop shadow: layers of each glyph, derived once, exact at any size.
    crisp::DrawOptions title;
    title.effects = crisp::TextEffects{};
    title.effects->outline = crisp::TextOutline{
        1.5f, crisp::OutlinePlacement::outside, crisp::LineJoin::round, 4.0f, {0.1f, 0.3f, 0.85f, 1.0f}};
    title.effects->shadow = crisp::TextShadow{2.0f, 2.0f, {0.0f, 0.0f, 0.0f, 0.6f}};
    renderer_->draw(title_.glyphs, title);
    renderer_->draw(paragraph_.glyphs);
    // Its underline: the layout's rectangles, drawn as panels beneath the text (whole pixels).
    for (const crisp::TextDecoration& d : paragraph_.decorations) {
        frame_.panels.push_back({std::round(d.x),
                                 std::round(d.y),
                                 std::round(d.width),
                                 std::max(1.0f, std::round(d.height)),
                                 {d.color[0], d.color[1], d.color[2], d.color[3]}});
    }
    // Text that changes every frame is laid out every frame: the Layouter keeps its buffers.
    char text[160];
    if (have_stats_) {
        std::snprintf(text, sizeof(text), "frame %llu   %u \xC3\x97 %u\n%u glyphs drawn, %u moving",
                      static_cast<unsigned long long>(frame), extent.width, extent.height, last_submitted_.drawn_glyphs,
                      last_submitted_.moving_glyphs);
    } else {
        std::snprintf(text, sizeof(text), "frame %llu   %u \xC3\x97 %u", static_cast<unsigned long long>(frame),
                      extent.width, extent.height);
    }
    if (lay_out(text, style(kCounterSize, kCounterColor), at(kHudX + kPadding, counter_y_, kCounterPaintOrder),
                counter_)) {
        renderer_->draw(counter_.glyphs);
    }
    frame_.boxes.push_back({"hud", hud_.x, hud_.y, hud_.width, hud_.height, false, 0.0f, 0.0f});
    frame_.boxes.push_back(box_of("paragraph", paragraph_, 0.0f, 0.0f));
    frame_.boxes.push_back(box_of("counter", counter_, 0.0f, 0.0f));
}

// The rows scroll up through the list box and wrap around; each keeps the layout it was given
// at start-up, and crisp clips it to the box.
void TextOverlay::draw_list(uint64_t frame) {
    // In doubles, and wrapped once per cycle, so that the rows keep their fractions however long
    // the program runs.
    const double speed = static_cast<double>(kScrollPerFrame);
    const double cycle_frames = static_cast<double>(rows_.size()) * static_cast<double>(kRowHeight) / speed;
    const auto scroll = static_cast<float>(std::fmod(static_cast<double>(frame), cycle_frames) * speed);
    const float cycle = static_cast<float>(rows_.size()) * kRowHeight;
    const float baseline = 3.0f + fonts_.front().ascender() * kRowSize;
    for (size_t i = 0; i < rows_.size(); ++i) {
        const float unwrapped = static_cast<float>(i) * kRowHeight - scroll;
        float top = unwrapped - std::floor(unwrapped / cycle) * cycle;
        if (top > cycle - kRowHeight) top -= cycle;  // leaving at the top, not yet back at the bottom
        crisp::DrawOptions options;
        options.offset_x = list_box_.x + 8.0f;
        options.offset_y = list_box_.y + top + baseline;
        options.visible = list_clip_;
        options.id = kRowId + i;
        renderer_->draw(rows_[i].glyphs, options);
    }
    frame_.boxes.push_back({"list", list_box_.x, list_box_.y, list_box_.width, list_box_.height, false, 0.0f, 0.0f});
}

// The spinner turns about its centre, which stays at the middle of its panel: the transform's pivot
// is the centre as laid out (at the origin) and the offset takes it to the panel's. A named draw
// whose transform changes is moving: its keys take the coarse linear steps (kMovingTransformSteps),
// so a turning label does not fill the atlas with an entry per angle.
void TextOverlay::draw_spinner(uint64_t frame) {
    // In doubles, and wrapped once per turn, so that the angle stays exact however long the program runs.
    const double degrees = std::fmod(static_cast<double>(frame) * kSpinPerFrame, 360.0);
    const auto radians = static_cast<float>(degrees * kPi / 180.0);
    const float cos_t = std::cos(radians), sin_t = std::sin(radians);
    const float pivot_x = spinner_.x + spinner_.width / 2.0f, pivot_y = spinner_.y + spinner_.height / 2.0f;
    crisp::DrawOptions options;
    options.transform = crisp::TextTransform{cos_t, -sin_t, sin_t, cos_t, pivot_x, pivot_y};  // clockwise, y down
    options.offset_x = spinner_panel_.x + spinner_panel_.width / 2.0f - pivot_x;
    options.offset_y = spinner_panel_.y + spinner_panel_.height / 2.0f - pivot_y;
    options.id = kSpinnerId;
    renderer_->draw(spinner_.glyphs, options);
    TextBox box = box_of("spinner", spinner_, options.offset_x, options.offset_y);
    box.angle = static_cast<float>(degrees);
    frame_.boxes.push_back(box);
}

void TextOverlay::draw_labels(VkExtent2D extent, const SceneState& scene) {
    struct Placed {
        size_t shape = 0;
        float x = 0.0f, y = 0.0f;  // the anchor on screen
        float depth = 0.0f;
    };
    std::vector<Placed> placed;
    const float width = static_cast<float>(extent.width), height = static_cast<float>(extent.height);
    for (size_t i = 0; i < kShapeCount; ++i) {
        const Vec3 anchor = scene.label_anchors[i];
        const float position[3] = {anchor.x, anchor.y, anchor.z};
        // nullopt behind the eye or past the far plane: no label.
        const std::optional<float> depth = crisp::depth_from_view_projection(scene.view_projection.m.data(), position);
        if (!depth) continue;
        const std::optional<std::array<float, 2>> at_window = to_window(scene.view_projection, anchor, width, height);
        if (!at_window) continue;
        placed.push_back({i, (*at_window)[0], (*at_window)[1], *depth});
    }
    // Hover: the label nearest the centre of the scene's part of the window.
    const float centre_x = (hud_right() + width) / 2.0f, centre_y = height / 2.0f;
    size_t hovered = kShapeCount;
    float nearest = std::numeric_limits<float>::infinity();
    for (const Placed& p : placed) {
        const float d = std::hypot(p.x - centre_x, p.y - centre_y);
        if (d < nearest) nearest = d, hovered = p.shape;
    }
    // Far to near, so that nearer backgrounds cover farther ones (crisp orders the text by depth).
    std::sort(placed.begin(), placed.end(), [](const Placed& a, const Placed& b) { return a.depth > b.depth; });
    for (const Placed& p : placed) {
        const crisp::TextLayout& label = labels_[p.shape];
        const bool hover = p.shape == hovered;
        crisp::DrawOptions options;
        options.offset_x = p.x - label.width / 2.0f - label.x;
        options.offset_y = p.y - kStem - kLabelMargin - (label.y + label.height);
        if (hover) options.color = kHoverColor;
        options.depth = p.depth;
        options.id = kLabelId + p.shape;
        renderer_->draw(label.glyphs, options);

        TextBox box = box_of("label", label, options.offset_x, options.offset_y);
        box.name = std::string("label:") + kShapeNames[p.shape];
        box.hovered = hover;
        box.anchor_x = p.x;
        box.anchor_y = p.y;
        frame_.boxes.push_back(box);
        frame_.panels.push_back({std::round(box.x - kLabelMargin), std::round(box.y - kLabelMargin),
                                 std::round(box.width + 2.0f * kLabelMargin),
                                 std::round(box.height + 2.0f * kLabelMargin), hover ? kHoverPanel : kLabelPanel});
        frame_.panels.push_back({std::round(p.x) - 1.0f, std::round(box.y + box.height + kLabelMargin), 2.0f,
                                 std::round(kStem - kLabelMargin), kMarker});
        frame_.panels.push_back({std::round(p.x) - 3.0f, std::round(p.y) - 3.0f, 6.0f, 6.0f, kMarker});
    }
}

// The sign lies on the cube's face: a plane through the face whose axes are world units per layout
// pixel, seen through the view-projection and the viewport the scene is drawn with. crisp places
// each glyph at the projection's local affine map at its centre (projective where that would be
// more than kMaxLocalAffineError px off), at its centre's depth. The face turns with the cube, so
// the draw is named and moving, as the spinner.
void TextOverlay::draw_sign(VkExtent2D extent, const SceneState& scene) {
    const SignFace& face = scene.sign;
    if (!face.facing) return;
    const float width = static_cast<float>(extent.width), height = static_cast<float>(extent.height);
    const float scale = kSignFill * 2.0f * face.half_side / sign_.width;  // world units per layout pixel
    const float centre_x = sign_.x + sign_.width / 2.0f, centre_y = sign_.y + sign_.height / 2.0f;
    crisp::TextPlane plane;
    plane.origin = to_array(face.centre - face.right * (centre_x * scale) - face.down * (centre_y * scale));
    plane.axis_x = to_array(face.right * scale);
    plane.axis_y = to_array(face.down * scale);
    plane.view_projection = scene.view_projection.m;
    plane.viewport = {0.0f, 0.0f, width, height};
    crisp::DrawOptions options;
    options.plane = plane;
    options.id = kSignId;
    renderer_->draw(sign_.glyphs, options);

    TextBox box;
    box.name = "sign";
    float x0 = width, y0 = height, x1 = 0.0f, y1 = 0.0f;
    const float corners[4][2] = {{-1.0f, -1.0f}, {1.0f, -1.0f}, {1.0f, 1.0f}, {-1.0f, 1.0f}};
    for (size_t i = 0; i < 4; ++i) {
        const Vec3 corner =
            face.centre + face.right * (corners[i][0] * face.half_side) + face.down * (corners[i][1] * face.half_side);
        const std::optional<std::array<float, 2>> at_window = to_window(scene.view_projection, corner, width, height);
        if (!at_window) return;  // crisp culls what is behind the eye; the report gets no box
        box.quad[i] = *at_window;
        x0 = std::min(x0, box.quad[i][0]), y0 = std::min(y0, box.quad[i][1]);
        x1 = std::max(x1, box.quad[i][0]), y1 = std::max(y1, box.quad[i][1]);
    }
    box.x = x0, box.y = y0, box.width = x1 - x0, box.height = y1 - y0;
    frame_.boxes.push_back(box);
}

// The field sits at the bottom of the scene's part of the window, right of the HUD, where it covers
// only the ground; it narrows with the window (and scrolls its text), down to nothing.
void TextOverlay::draw_field(VkExtent2D extent) {
    const float x = hud_right() + kFieldGap;
    const float width = std::clamp(static_cast<float>(extent.width) - x - kFieldGap, 0.0f, kFieldMaxWidth);
    const float y = std::max(static_cast<float>(extent.height) - kFieldHeight - kFieldGap, 0.0f);
    field_->place({x, y, width, kFieldHeight});
    field_->draw(*renderer_, frame_.panels, kFieldId);
}

crisp::Status TextOverlay::record_rasterization(VkCommandBuffer command_buffer) {
    return renderer_->record(command_buffer);
}

crisp::Status TextOverlay::record_composite(VkCommandBuffer command_buffer, const RenderTargets& targets) {
    crisp::CompositeTarget target;
    target.view = targets.color.view.get();
    target.format = kSceneColorFormat;
    target.extent = targets.color.extent;
    target.rect = {{0, 0}, targets.color.extent};
    crisp::Status status = compositor_->record(command_buffer, renderer_->drawn_frame(), target);
    return status;
}

// Both take back this frame only, named by the renderer's number for it: where this frame's
// compositing failed or never came, the compositor's last record is the last submitted frame's,
// and it refuses (keeping it) rather than take that one back.
void TextOverlay::abandon_frame() {
    const uint64_t frame = renderer_->frame();
    const crisp::Status renderer_taken = renderer_->abandon_frame(frame);      // the current frame: never refused
    const crisp::Status compositor_taken = compositor_->abandon_frame(frame);  // refused when not composited
    (void)renderer_taken;
    (void)compositor_taken;
}

void TextOverlay::frame_submitted() {
    last_submitted_ = renderer_->stats();
    have_stats_ = true;
    submitted_glyphs_ = {last_submitted_.drawn_glyphs, last_submitted_.moving_glyphs, 0, 0};
    for (const crisp::DrawnGlyph& glyph : renderer_->drawn_frame().glyphs) {
        const crisp::GlyphKey& key = glyph.instance.key;
        submitted_glyphs_.transformed += crisp::is_transformed(key) ? 1u : 0u;
        submitted_glyphs_.projective += key.perspective[0] != 0 || key.perspective[1] != 0 ? 1u : 0u;
    }
}

}  // namespace engine
