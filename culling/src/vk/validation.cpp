#include "vk/validation.hpp"

#include <atomic>
#include <cstdlib>
#include <cstring>
#include <mutex>

namespace lc::vk {
namespace {
std::mutex gMutex;
std::vector<std::string> gMessages;
std::atomic<bool> gLayerActive{false}, gSyncActive{false};
} // namespace

bool validationRequested() {
    const char* v = std::getenv("LIGHTCULL_VALIDATION");
    return v && std::strcmp(v, "1") == 0;
}
std::vector<std::string> validationMessages() {
    std::lock_guard<std::mutex> lock(gMutex);
    return gMessages;
}
void clearValidationMessages() {
    std::lock_guard<std::mutex> lock(gMutex);
    gMessages.clear();
}
void eraseValidationMessagesFrom(std::size_t count) {
    std::lock_guard<std::mutex> lock(gMutex);
    if (gMessages.size() > count) gMessages.resize(count);
}
void recordValidationMessage(const std::string& message) {
    std::lock_guard<std::mutex> lock(gMutex);
    gMessages.push_back(message);
}
bool validationLayerActive() { return gLayerActive; }
void markValidationLayerActive() { gLayerActive = true; }
bool syncValidationActive() { return gSyncActive; }
void markSyncValidationActive() { gSyncActive = true; }

} // namespace lc::vk
