#pragma once
// The process's Embree device, shared by every resident brick. Embree types stay in the .cpp files.

#include <memory>
#include <mutex>
#include <string>

#include "src/core/status.h"

namespace nave::render {

/// The process's Embree device. Embree errors reported through its callback are kept and turned
/// into a Status by the call that caused them.
class EmbreeDevice {
  public:
    /// `config` is Embree's device configuration string ("threads=4"); empty for the defaults.
    static StatusOr<std::shared_ptr<EmbreeDevice>> Create(const std::string& config = "");
    ~EmbreeDevice();
    EmbreeDevice(const EmbreeDevice&) = delete;
    EmbreeDevice& operator=(const EmbreeDevice&) = delete;

    void* handle() const { return device_; }  // RTCDevice
    /// The last error reported by Embree's callback (and clears it), or Ok.
    Status TakeError(const std::string& context);

  private:
    EmbreeDevice() = default;
    static void ErrorCallback(void* user, int code, const char* message);
    void* device_ = nullptr;
    std::mutex mutex_;
    Status error_;
};

}  // namespace nave::render
