package org.phantogram;

import java.nio.ByteBuffer;

/**
 * The native methods of libphantogram_android.so (android/src/jni_bridge.rs). This file is the
 * one declaration of them: the app compiles it, and the desktop JVM test compiles it unchanged
 * against the host build of the same library, so the two cannot drift. It uses no Android class
 * (the surface is passed as an Object) for that reason.
 *
 * Threading: the sensor and camera methods may be called from any thread at any time and never
 * wait for a frame; the others serialise on the engine. nativeSurfaceDestroyed returns once the
 * native window is released. nativeDestroy must not race any other call on the same handle.
 *
 * Errors: IllegalArgumentException (bad arguments), IllegalStateException (wrong state, e.g. a
 * destroyed handle), UnsupportedOperationException (not on this platform), RuntimeException
 * (loading or GPU failures, and internal errors). Native panics never reach the JVM as crashes.
 *
 * Times are nanoseconds on the sensor clock (SensorEvent.timestamp, i.e.
 * SystemClock.elapsedRealtimeNanos()); the shell converts Choreographer and MotionEvent times.
 */
public final class NativeBridge {
    private NativeBridge() {}

    /** Loads the library (the app: by name; the desktop test: by path). */
    public static void load(String absolutePathOrNull) {
        if (absolutePathOrNull == null) {
            System.loadLibrary("phantogram_android");
        } else {
            System.load(absolutePathOrNull);
        }
    }

    /** Gesture codes returned by nativeTouch. */
    public static final int GESTURE_NONE = 0;
    public static final int GESTURE_STRAIGHT_ON = 1;
    public static final int GESTURE_LIGHT_ANCHORED = 2;
    public static final int GESTURE_STEREO_TOGGLED = 3;
    /** Three-finger tap: the calibration screens opened; touches drive them until closed. */
    public static final int GESTURE_CALIBRATION_OPENED = 4;
    /** Single tap: the menu (artifacts, calibration) opened; touches drive it until closed. */
    public static final int GESTURE_MENU_OPENED = 5;

    /** Touch phases for nativeTouch. */
    public static final int TOUCH_DOWN = 0;
    public static final int TOUCH_MOVE = 1;
    public static final int TOUCH_UP = 2;
    public static final int TOUCH_CANCEL = 3;

    /** Opens the GPU device and loads the scene; call off the UI thread. Null strings: defaults
     *  (a null calibrationPath: the viewer's calibration is neither read nor saved; a null
     *  libraryDir: nothing can be imported; artifactId: the id saved from nativeCurrentArtifact
     *  last time, or null for the default artifact). */
    public static native long nativeCreate(String modelPath, String faceModelsDir, int panelWidthPx,
            int panelHeightPx, float xdpi, float ydpi, int rotation, String anaglyph,
            String calibrationPath, String libraryDir, String bundledDir, String artifactId);

    public static native void nativeDestroy(long handle);

    /** One SensorEvent (Sensor.TYPE_*); w is NaN when the event has three values. */
    public static native boolean nativePushSensor(long handle, int sensorType, long timestampNs,
            float x, float y, float z, float w);

    /** The front camera: face tracking and the room light. */
    public static final int CAMERA_FRONT = 0;
    /** The rear camera, where the device runs both at once: the room light. */
    public static final int CAMERA_REAR = 1;

    /**
     * A YUV_420_888 frame of the camera (CAMERA_FRONT or CAMERA_REAR): the Y plane (direct buffer,
     * pixel stride 1) and the Cb and Cr planes (direct buffers with their row and pixel strides;
     * both null for luma only); all copied before returning. Returns false when nothing took it
     * (front: face tracking off; rear: the room light off).
     */
    public static native boolean nativeCameraFrame(long handle, int camera, ByteBuffer luma, int width, int height,
            int rowStride, ByteBuffer cb, ByteBuffer cr, int chromaRowStride, int chromaPixelStride,
            int rotationDegrees, float fx, float fy, float cx, float cy, long timestampNs);

    /**
     * The exposure of the camera's frame captured at timestampNs, from its capture result
     * (SENSOR_EXPOSURE_TIME in ns, SENSOR_SENSITIVITY, LENS_APERTURE or NaN); matched to the
     * frame by the core.
     */
    public static native boolean nativeCameraExposure(long handle, int camera, long timestampNs, long exposureTimeNs,
            int iso, float aperture);

    /**
     * [fx, fy, cx, cy] of a width × height output image from Camera2's characteristics as
     * reported: rects as [left, top, right, bottom], sizes as [width, height], focalLengthMm NaN
     * when unknown, optional arrays null. Throws IllegalArgumentException when they give none.
     */
    public static native float[] nativeCameraIntrinsics(int[] activeArray, int[] preCorrection,
            int[] pixelArray, float[] physicalSizeMm, float focalLengthMm, float[] lensCalibration,
            int width, int height);

    public static native int nativeTouch(long handle, int phase, int pointerId, float x, float y, long timeNs);

    /** surface is an android.view.Surface. */
    public static native void nativeSurfaceCreated(long handle, Object surface, int width, int height);

    public static native void nativeResumeOffscreen(long handle, int width, int height);

    public static native void nativeSurfaceChanged(long handle, int width, int height);

    public static native void nativeSurfaceDestroyed(long handle);

    public static native void nativeSetDisplay(long handle, int panelWidthPx, int panelHeightPx,
            float xdpi, float ydpi, int rotation);

    public static native void nativeSetAnaglyph(long handle, String name);

    /** Sensor.getMaximumRange() of the accelerometer (m/s^2) and gyroscope (rad/s); 0 if absent. */
    public static native void nativeSetSensorRanges(long handle, float accelMaxRange, float gyroMaxRange);

    /** Draws the frame shown at displayTimeNs (negative: no prediction); false if skipped. */
    public static native boolean nativeDrawFrame(long handle, long displayTimeNs);

    /** The last offscreen frame: [width, height, ARGB pixels...]. */
    public static native int[] nativeReadFrame(long handle);

    /** [framesDrawn, framesSkipped, resumed, suspended, sensorsAccepted, sensorsRejected,
     *  cameraFrames, gestures, eyesFromCamera]. */
    public static native long[] nativeStats(long handle);

    /** Why the calibration file could not be read, applied or saved, for the log; null when all is
     *  well. The engine runs on regardless. */
    public static native String nativeCalibrationWarning(long handle);

    /** Requests of the core's screens, from nativeTakeShellRequest. */
    public static final int REQUEST_NONE = 0;
    /** Show ACTION_OPEN_DOCUMENT for a .glb, .gltf, .stl, .ply, .obj or .zip, then nativeImportArtifactFd. */
    public static final int REQUEST_OPEN_FILE = 1;
    /** Ask for the CAMERA permission (the core's camera page has said why); start the camera
     *  when granted. */
    public static final int REQUEST_CAMERA_PERMISSION = 2;
    /** Share the view as the anaglyph picture: nativeSnapshotPng(handle, 0) to the share sheet. */
    public static final int REQUEST_SHARE_PICTURE = 3;
    /** Share the view as a side-by-side stereo pair: nativeSnapshotPng(handle, 1). */
    public static final int REQUEST_SHARE_PAIR = 4;
    /** The room light is on: run the rear camera beside the front one where the device can. */
    public static final int REQUEST_REAR_CAMERA_ON = 5;
    /** The room light is off: the front camera alone (the rear one would cost power for nothing). */
    public static final int REQUEST_REAR_CAMERA_OFF = 6;

    /** The system's font scale (Configuration.fontScale): the core's screens scale their text
     *  and controls by it (0.85 to 2). IllegalArgumentException for a non-positive scale. */
    public static native void nativeSetTextScale(long handle, float scale);

    /** The app has no camera permission yet and may ask: the core explains first, then asks
     *  with REQUEST_CAMERA_PERMISSION if the user wants the camera. */
    public static native void nativeCameraPermissionNeeded(long handle);

    /** Imports a file the user opened (display name, bytes); loaded in the background, the
     *  core's banner shows progress or the reason it failed. */
    public static native void nativeImportArtifact(long handle, String name, byte[] bytes);

    /** As nativeImportArtifact from ParcelFileDescriptor.detachFd(): the library owns and closes
     *  the descriptor and reads it off the calling thread. */
    public static native void nativeImportArtifactFd(long handle, String name, int fd);

    /** Shows an artifact of the library by id ("builtin:medal", "imported:..."). */
    public static native void nativeSelectArtifact(long handle, String id);

    /** The id of the artifact on screen (save it for nativeCreate); null for a file by path. */
    public static native String nativeCurrentArtifact(long handle);

    /** Opens the menu (gallery, open a file, calibration), as a single tap does. */
    public static native void nativeOpenMenu(long handle);

    /** The oldest request of the core's screens (REQUEST_*); call after each frame. */
    public static native int nativeTakeShellRequest(long handle);

    /** [state, fraction]: 0 idle, 1 loading (fraction 0..1), 2 the last load failed. */
    public static native float[] nativeLoadingState(long handle);

    /** The current view as PNG bytes for the share sheet: 0 anaglyph, 1 side by side. */
    public static native byte[] nativeSnapshotPng(long handle, int kind);

    /**
     * One thing a screen reader (TalkBack) can land on in the core's screens: a virtual view of
     * the drawing surface. Bounds in the surface's pixels. The ids are small, positive and
     * stable for a control while the engine lives.
     */
    public static final class AccessibilityNode {
        public static final int ROLE_TEXT = 0;
        public static final int ROLE_BUTTON = 1;
        public static final int ROLE_CHECK_BOX = 2;
        public static final int ROLE_RADIO_BUTTON = 3;
        public static final int ROLE_SLIDER = 4;
        public static final int ROLE_IMAGE = 5;

        /** Activating it does something (nativeAccessibilityClick). */
        public static final int FLAG_CLICKABLE = 1;
        /** It steps up and down (nativeAccessibilityAdjust): a slider. */
        public static final int FLAG_ADJUSTABLE = 2;
        /** It has an on/off state, given by FLAG_CHECKED. */
        public static final int FLAG_CHECKABLE = 4;
        public static final int FLAG_CHECKED = 8;
        public static final int FLAG_DISABLED = 16;

        public final int id;
        public final int role;
        public final int flags;
        public final float left;
        public final float top;
        public final float right;
        public final float bottom;
        /** What to say; never empty. */
        public final String label;
        /** A slider's value as text, or null. */
        public final String value;

        public AccessibilityNode(int id, int role, int flags, float left, float top, float right,
                float bottom, String label, String value) {
            this.id = id;
            this.role = role;
            this.flags = flags;
            this.left = left;
            this.top = top;
            this.right = right;
            this.bottom = bottom;
            this.label = label;
            this.value = value;
        }

        public boolean has(int flag) {
            return (flags & flag) != 0;
        }
    }

    /** What a screen reader can land on in the last frame, in reading order (the open screen's
     *  text and controls, or the picture itself). Read it again when nativeAccessibilityGeneration
     *  changes (after a frame). */
    public static native AccessibilityNode[] nativeAccessibilityNodes(long handle);

    /** Changes whenever nativeAccessibilityNodes would return something else. */
    public static native long nativeAccessibilityGeneration(long handle);

    /** A screen reader's activation of node id: it acts in the next frame as if tapped. False
     *  for an id not on screen now, or one that does nothing. */
    public static native boolean nativeAccessibilityClick(long handle, int id);

    /** A screen reader's step up (steps > 0) or down on slider id, applied in the next frame.
     *  False for an id that is not an adjustable node now. */
    public static native boolean nativeAccessibilityAdjust(long handle, int id, int steps);
}
