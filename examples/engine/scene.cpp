#include "scene.hpp"

#include <cstring>
#include <vector>

namespace engine {
namespace {

constexpr float kPi = 3.14159265358979f;
constexpr std::array<float, 4> kClearColor = {0.030f, 0.040f, 0.062f, 1.0f};  // linear night blue

// Each shape: where it stands, how it turns and bobs per frame, how far above its origin its
// label floats.
struct ShapeMotion {
    Vec3 position;
    float spin = 0.0f;       // radians per frame about y
    float bob = 0.0f;        // amplitude in world units
    float bob_speed = 0.0f;  // radians per frame
    float label_height = 0.0f;
};
constexpr std::array<ShapeMotion, kShapeCount> kMotions = {{
    {{-1.9f, 0.6f, 0.6f}, 0.013f, 0.0f, 0.0f, 1.2f},
    {{0.2f, 1.35f, -1.3f}, -0.021f, 0.22f, 0.045f, 1.2f},
    {{1.9f, 0.55f, 1.0f}, 0.017f, 0.0f, 0.0f, 1.05f},
}};

// Triangles with flat normals; each face is wound counter-clockwise seen from outside, decided
// from a point inside the solid.
class MeshBuilder {
public:
    explicit MeshBuilder(std::vector<Vertex>& out) : out_(out) {}
    void triangle(Vec3 a, Vec3 b, Vec3 c, Vec3 inside, Vec3 color) {
        Vec3 normal = normalize(cross(b - a, c - a));
        if (dot(normal, a - inside) < 0.0f) {
            std::swap(b, c);
            normal = normal * -1.0f;
        }
        for (Vec3 p : {a, b, c}) {
            out_.push_back({{p.x, p.y, p.z}, {normal.x, normal.y, normal.z}, {color.x, color.y, color.z}});
        }
    }
    void quad(Vec3 a, Vec3 b, Vec3 c, Vec3 d, Vec3 inside, Vec3 color) {
        triangle(a, b, c, inside, color);
        triangle(a, c, d, inside, color);
    }

private:
    std::vector<Vertex>& out_;
};

void build_ground(MeshBuilder& mesh) {
    constexpr int kTiles = 28;
    constexpr float kTile = 1.0f;
    const Vec3 light{0.15f, 0.16f, 0.17f}, dark{0.085f, 0.09f, 0.10f};
    for (int z = 0; z < kTiles; ++z) {
        for (int x = 0; x < kTiles; ++x) {
            const float x0 = (static_cast<float>(x) - kTiles / 2.0f) * kTile,
                        z0 = (static_cast<float>(z) - kTiles / 2.0f) * kTile;
            mesh.quad({x0, 0, z0}, {x0 + kTile, 0, z0}, {x0 + kTile, 0, z0 + kTile}, {x0, 0, z0 + kTile}, {0, -1, 0},
                      (x + z) % 2 ? light : dark);
        }
    }
}

constexpr float kCubeHalfSide = 0.6f;

void build_cube(MeshBuilder& mesh) {
    constexpr float h = kCubeHalfSide;
    const Vec3 color{0.80f, 0.22f, 0.10f};
    for (int axis = 0; axis < 3; ++axis) {
        for (float sign : {-1.0f, 1.0f}) {
            // The face's corners: the axis fixed at sign * h, the other two at +-h.
            auto corner = [&](float u, float v) {
                float p[3] = {};
                p[axis] = sign * h;
                p[(axis + 1) % 3] = u * h;
                p[(axis + 2) % 3] = v * h;
                return Vec3{p[0], p[1], p[2]};
            };
            mesh.quad(corner(-1, -1), corner(1, -1), corner(1, 1), corner(-1, 1), {}, color);
        }
    }
}

void build_octahedron(MeshBuilder& mesh) {
    constexpr float r = 0.85f;
    const Vec3 color{0.16f, 0.36f, 0.85f};
    for (float sx : {-r, r}) {
        for (float sy : {-r, r}) {
            for (float sz : {-r, r}) mesh.triangle({sx, 0, 0}, {0, sy, 0}, {0, 0, sz}, {}, color);
        }
    }
}

void build_pyramid(MeshBuilder& mesh) {
    constexpr float h = 0.7f, base = -0.55f, top = 0.75f;
    const Vec3 color{0.22f, 0.62f, 0.24f};
    const Vec3 inside{0, 0, 0};
    const Vec3 corners[4] = {{-h, base, -h}, {h, base, -h}, {h, base, h}, {-h, base, h}};
    for (int i = 0; i < 4; ++i) mesh.triangle(corners[i], corners[(i + 1) % 4], {0, top, 0}, inside, color);
    mesh.quad(corners[0], corners[1], corners[2], corners[3], inside, color);
}

}  // namespace

crisp::Result<Scene> Scene::create(const Device& device, VkFormat depth_format) {
    std::vector<Vertex> vertices;
    MeshBuilder builder(vertices);
    Scene scene;
    auto add = [&](Mesh& mesh, void (*build)(MeshBuilder&)) {
        mesh.first = static_cast<uint32_t>(vertices.size());
        build(builder);
        mesh.count = static_cast<uint32_t>(vertices.size()) - mesh.first;
    };
    add(scene.ground_, build_ground);
    add(scene.shapes_[0], build_cube);
    add(scene.shapes_[1], build_octahedron);
    add(scene.shapes_[2], build_pyramid);

    crisp::Result<Buffer> buffer =
        create_host_buffer(device.memory(), vertices.size() * sizeof(Vertex), VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
    if (!buffer) return buffer.error();
    scene.vertices_ = std::move(*buffer);
    std::memcpy(scene.vertices_.mapped, vertices.data(), vertices.size() * sizeof(Vertex));
    crisp::Result<Pipelines> pipelines = create_pipelines(device.device(), kSceneColorFormat, depth_format);
    if (!pipelines) return pipelines.error();
    scene.pipelines_ = std::move(*pipelines);
    return scene;
}

SceneState Scene::animate(uint64_t frame, VkExtent2D extent, float scene_left) {
    const auto t = static_cast<float>(frame);
    const float orbit = 0.35f + t * 0.0035f;  // the camera circles the scene slowly
    const Vec3 eye{9.5f * std::sin(orbit), 5.0f, 9.5f * std::cos(orbit)};
    const float width = static_cast<float>(extent.width), height = static_cast<float>(extent.height);
    const float shift = std::min(scene_left / width, 0.5f);  // centre of the part right of the HUD
    const Mat4 projection = perspective(40.0f * kPi / 180.0f, width / height, 0.1f, 60.0f, shift);
    SceneState state;
    state.view_projection = projection * look_at(eye, {0.0f, 0.9f, 0.0f}, {0.0f, 1.0f, 0.0f});
    state.ground = Mat4::identity();
    for (size_t i = 0; i < kShapeCount; ++i) {
        const ShapeMotion& m = kMotions[i];
        const Vec3 position = m.position + Vec3{0.0f, m.bob * std::sin(t * m.bob_speed), 0.0f};
        state.shapes[i] = translation(position) * rotation_y(t * m.spin);
        state.label_anchors[i] = position + Vec3{0.0f, m.label_height, 0.0f};
    }
    const Mat4& cube = state.shapes[0];
    const std::array<float, 4> centre = transform_point(cube, {0.0f, 0.0f, kCubeHalfSide});
    SignFace& sign = state.sign;
    sign.centre = {centre[0], centre[1], centre[2]};
    sign.right = transform_direction(cube, {1.0f, 0.0f, 0.0f});
    sign.down = transform_direction(cube, {0.0f, -1.0f, 0.0f});
    sign.half_side = kCubeHalfSide;
    sign.facing = dot(transform_direction(cube, {0.0f, 0.0f, 1.0f}), eye - sign.centre) > 0.0f;
    return state;
}

void Scene::record(VkCommandBuffer cb, const RenderTargets& targets, const SceneState& state,
                   std::span<const Panel> panels) const {
    // Last frame's blit read the colour target; its depth was last written by last frame's tests.
    record_barrier(cb, {targets.color.image.get(), VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                        VK_PIPELINE_STAGE_TRANSFER_BIT, 0, VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
                        VK_ACCESS_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT});
    const VkPipelineStageFlags tests =
        VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT;
    record_barrier(cb, {targets.depth.image.get(), VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
                        tests, VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT, tests,
                        VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
                        VK_IMAGE_ASPECT_DEPTH_BIT});

    VkRenderingAttachmentInfo color{};
    color.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO;
    color.imageView = targets.color.view.get();
    color.imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
    color.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
    color.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    std::memcpy(color.clearValue.color.float32, kClearColor.data(), sizeof(float) * 4);
    VkRenderingAttachmentInfo depth{};
    depth.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO;
    depth.imageView = targets.depth.view.get();
    depth.imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL;
    depth.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
    depth.storeOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
    depth.clearValue.depthStencil = {1.0f, 0};
    const VkExtent2D extent = targets.color.extent;
    VkRenderingInfo rendering{};
    rendering.sType = VK_STRUCTURE_TYPE_RENDERING_INFO;
    rendering.renderArea = {{0, 0}, extent};
    rendering.layerCount = 1;
    rendering.colorAttachmentCount = 1;
    rendering.pColorAttachments = &color;
    rendering.pDepthAttachment = &depth;
    vkCmdBeginRendering(cb, &rendering);
    const VkViewport viewport{0.0f, 0.0f, static_cast<float>(extent.width), static_cast<float>(extent.height),
                              0.0f, 1.0f};
    const VkRect2D scissor{{0, 0}, extent};
    vkCmdSetViewport(cb, 0, 1, &viewport);
    vkCmdSetScissor(cb, 0, 1, &scissor);

    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, pipelines_.scene.get());
    const VkBuffer buffer = vertices_.buffer.get();
    const VkDeviceSize offset = 0;
    vkCmdBindVertexBuffers(cb, 0, 1, &buffer, &offset);
    auto draw_mesh = [&](const Mesh& mesh, const Mat4& model) {
        const ScenePush push{state.view_projection * model, model};
        vkCmdPushConstants(cb, pipelines_.scene_layout.get(), VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT,
                           0, sizeof(push), &push);
        vkCmdDraw(cb, mesh.count, 1, mesh.first, 0);
    };
    draw_mesh(ground_, state.ground);
    for (size_t i = 0; i < kShapeCount; ++i) draw_mesh(shapes_[i], state.shapes[i]);

    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, pipelines_.panel.get());
    for (const Panel& panel : panels) {
        const PanelPush push{{panel.x, panel.y, panel.width, panel.height},
                             {panel.color[0], panel.color[1], panel.color[2], panel.color[3]},
                             {viewport.width, viewport.height}};
        vkCmdPushConstants(cb, pipelines_.panel_layout.get(), VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT,
                           0, sizeof(push), &push);
        vkCmdDraw(cb, 4, 1, 0, 0);
    }
    vkCmdEndRendering(cb);
}

}  // namespace engine
