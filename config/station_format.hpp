#pragma once
// The station config format as tables (see field_spec.hpp). The camera and PLC sections mirror
// the camera module's CameraSettings and the PLC module's PlcSettings / RegisterMap key by key.

#include "config/field_spec.hpp"

namespace facet::config {

struct StationFormat {
  ObjectSpec station;
  ObjectSpec camera, replay, aravis, v4l2, scans;
  ObjectSpec plc, registerMap, control, status, location, result;
  ObjectSpec results, archive, http, calibration;
  ObjectSpec mqtt, mqttTls, postgres;  // results to a fleet (fleet_settings.hpp)

  StationFormat();
  StationFormat(const StationFormat&) = delete;  // the tables point into themselves
  StationFormat& operator=(const StationFormat&) = delete;
};

const StationFormat& stationFormat();

}  // namespace facet::config
