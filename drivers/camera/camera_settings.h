// The camera's settings, with their defaults; the config file (app/config/) fills this struct.
#pragma once

#include <string>

namespace avatarbooth {

struct CameraSettings {
    // Which camera stack: "auto" (a V4L2 device offering YUYV/MJPEG if there is one, else a libcamera camera,
    // else the simulated camera; the choice is logged and shown in the description), "v4l2", "libcamera", "sim".
    std::string backend = "auto";
    // v4l2: the device node, e.g. "/dev/video0" or a stable "/dev/v4l/by-id/..." name (a USB camera may come back
    // under another /dev/videoN after a replug); "" = the first /dev/video* that can stream YUYV or MJPEG.
    // libcamera: the camera id as listed by `avatarbooth check`; "" = the first camera.
    std::string device;

    // Preview stream (what the guide screens show and face guidance reads): the wanted size and rate. The
    // nearest the device offers is used (see negotiateV4l2Format).
    int previewWidth = 1280;
    int previewHeight = 720;
    double previewFps = 30;
    // Still (the photo that is fitted): the wanted size; 0 x 0 = the largest the device offers.
    int stillWidth = 0;
    int stillHeight = 0;
    // Frames thrown away after switching to the still format, while exposure and white balance settle.
    int stillWarmupFrames = 3;
    // Driver buffers for streaming (V4L2 mmap buffers, libcamera requests).
    int bufferCount = 4;

    // Simulated camera: a recorded session folder (front.*, side.*, optional background.*; jpg or png).
    std::string simFolder;
    // Its frame rate; timestamps advance by exactly 1/simFps.
    double simFps = 30;
    // true: frames come at simFps in real time; false: as fast as they are asked for (time still advances by
    // 1/simFps per frame), for tests and batch runs.
    bool simRealTime = true;
    // Per-frame sensor noise added to preview frames, in grey levels (+-); 0 = identical frames.
    int simNoise = 2;

    // Reopening a camera that went away: the first retry after this many seconds, then doubling up to the max.
    double reopenFirstDelaySeconds = 0.5;
    double reopenMaxDelaySeconds = 8;
};

}  // namespace avatarbooth
