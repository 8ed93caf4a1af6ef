#pragma once
// Internal, for tests and diagnostics: what the Khronos validation layer said.
//
// When the environment has LIGHTCULL_VALIDATION=1, every Vulkan instance the
// backend creates enables VK_LAYER_KHRONOS_validation with synchronisation
// validation and a debug messenger that records every warning and error here.
// Tests assert the list is empty at the end (any message fails them).
#include <cstddef>
#include <string>
#include <vector>

namespace lc::vk {

// True when LIGHTCULL_VALIDATION=1 is set in the environment.
bool validationRequested();
// Messages (warnings and errors) recorded since the last clear, all instances.
std::vector<std::string> validationMessages();
void clearValidationMessages();
// Removes the messages recorded after the first `count` (a custom shader's
// messages are reported as its own, not as failures of the built-in passes).
void eraseValidationMessagesFrom(std::size_t count);
// Records one message (called by the debug messenger).
void recordValidationMessage(const std::string& message);
// True once an instance was created with the validation layer enabled (and
// the layer was enumerated by the loader). Reset never.
bool validationLayerActive();
void markValidationLayerActive();
// Whether synchronisation validation was enabled through VkValidationFeaturesEXT.
bool syncValidationActive();
void markSyncValidationActive();

} // namespace lc::vk
