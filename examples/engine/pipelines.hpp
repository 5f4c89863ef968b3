// The engine's two graphics pipelines, both for dynamic rendering into the scene target with its
// depth buffer: lit shapes (depth-tested) and flat panels (blended, no depth).
#pragma once

#include "math.hpp"
#include "vk_objects.hpp"

#include <crisp/result.hpp>

#include <volk.h>

namespace engine {

struct Vertex {
    float position[3];
    float normal[3];
    float color[3];  // linear
};

struct ScenePush {
    Mat4 model_view_projection;
    Mat4 model;
};
static_assert(sizeof(ScenePush) == 128, "scene.vert's push constants");

struct PanelPush {
    float rect[4];   // x, y, width, height in window pixels
    float color[4];  // linear, straight alpha
    float viewport[2];
};
static_assert(sizeof(PanelPush) == 40, "panel.vert's push constants");

struct Pipelines {
    OwnedPipelineLayout scene_layout;
    OwnedPipeline scene;
    OwnedPipelineLayout panel_layout;
    OwnedPipeline panel;
};

// Viewport and scissor are dynamic: a resize needs no new pipeline.
crisp::Result<Pipelines> create_pipelines(VkDevice device, VkFormat color_format, VkFormat depth_format);

}  // namespace engine
