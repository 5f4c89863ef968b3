// The example engine's 3D scene: a checkered ground and three lit shapes, animated by the frame
// index, drawn depth-tested into the HDR scene target, then the flat panels (HUD, label
// backgrounds) over them. crisp's text is composited into the same target afterwards.
#pragma once

#include "device.hpp"
#include "math.hpp"
#include "pipelines.hpp"
#include "swapchain.hpp"
#include "vk_objects.hpp"

#include <crisp/result.hpp>

#include <array>
#include <cstdint>
#include <span>

namespace engine {

inline constexpr size_t kShapeCount = 3;
// The shapes' names, which their labels show.
inline constexpr std::array<const char*, kShapeCount> kShapeNames = {"Cube", "Octahedron", "Pyramid"};

// The cube's face that carries a sign (its +z face, turning with the cube), in world space.
struct SignFace {
    Vec3 centre;
    Vec3 right;  // unit vectors along the face: as the sign's text reads, and down its lines
    Vec3 down;
    float half_side = 0.0f;  // world units from the centre to each edge
    // The eye sees the face's front. The tile path draws text over the scene, so a face turned
    // away gets no sign (the cube is convex: a face the eye sees is never behind the cube itself).
    bool facing = false;
};

// Where everything is in one frame.
struct SceneState {
    Mat4 view_projection;
    Mat4 ground;
    std::array<Mat4, kShapeCount> shapes;
    std::array<Vec3, kShapeCount> label_anchors;  // world position just above each shape
    SignFace sign;
};

// A filled rectangle in window pixels, linear colour with straight alpha.
struct Panel {
    float x = 0.0f, y = 0.0f, width = 0.0f, height = 0.0f;
    std::array<float, 4> color{};
};

class Scene {
public:
    static crisp::Result<Scene> create(const Device& device, VkFormat depth_format);

    // The scene at frame `frame` (the index of presented frames: animation never reads a clock, so
    // two runs of N frames draw the same N images). The image is centred in the part of the window
    // right of `scene_left` pixels.
    static SceneState animate(uint64_t frame, VkExtent2D extent, float scene_left);

    // Clears `targets`, draws the shapes and then `panels` in order. On return the colour target is
    // in COLOR_ATTACHMENT_OPTIMAL, written at COLOR_ATTACHMENT_OUTPUT. The colour target's previous
    // contents (last frame's, read by its blit) are discarded.
    void record(VkCommandBuffer command_buffer, const RenderTargets& targets, const SceneState& state,
                std::span<const Panel> panels) const;

private:
    struct Mesh {
        uint32_t first = 0;
        uint32_t count = 0;
    };
    Buffer vertices_;
    Mesh ground_;
    std::array<Mesh, kShapeCount> shapes_{};
    Pipelines pipelines_;
};

}  // namespace engine
