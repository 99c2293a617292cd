// A part that holds files a firmware can print from (an SD card): the bench
// asks it for the file a host selected (M23) when the firmware starts
// printing it (M24), so the motion judges know what the firmware was told.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "parts/FatVolume.hpp"

namespace avrbench {

class StoredFiles {
public:
    virtual ~StoredFiles() = default;
    // The files as the firmware would read them now; empty when the bench
    // cannot read the medium (no file system it knows, no card in the slot).
    virtual std::optional<std::vector<FatFile>> stored_files() const = 0;
};

}  // namespace avrbench
