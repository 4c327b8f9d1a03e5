#include "src/render/bricks/embree_device.h"

#include <embree3/rtcore.h>
#include <fmt/format.h>

#include <mutex>

namespace nave::render {

StatusOr<std::shared_ptr<EmbreeDevice>> EmbreeDevice::Create(const std::string& config) {
    std::shared_ptr<EmbreeDevice> device(new EmbreeDevice());
    RTCDevice handle = rtcNewDevice(config.empty() ? nullptr : config.c_str());
    if (handle == nullptr) {
        return InternalError("Embree: cannot create a device with config '{}' (error {})", config,
                             int(rtcGetDeviceError(nullptr)));
    }
    device->device_ = handle;
    rtcSetDeviceErrorFunction(
        handle,
        [](void* user, RTCError code, const char* message) {
            EmbreeDevice::ErrorCallback(user, int(code), message);
        },
        device.get());
    return device;
}

EmbreeDevice::~EmbreeDevice() {
    if (device_ != nullptr) rtcReleaseDevice(static_cast<RTCDevice>(device_));
}

void EmbreeDevice::ErrorCallback(void* user, int code, const char* message) {
    auto* self = static_cast<EmbreeDevice*>(user);
    std::lock_guard<std::mutex> lock(self->mutex_);
    if (self->error_.ok()) {
        self->error_ =
            Status(code == RTC_ERROR_OUT_OF_MEMORY ? StatusCode::kResourceExhausted
                                                   : StatusCode::kInternal,
                   fmt::format("Embree error {}: {}", code, message ? message : "(no message)"));
    }
}

Status EmbreeDevice::TakeError(const std::string& context) {
    std::lock_guard<std::mutex> lock(mutex_);
    Status s = error_;
    error_ = Status::Ok();
    return s.ok() ? s : s.WithContext(context);
}

}  // namespace nave::render
