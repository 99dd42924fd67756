import java.io.BufferedReader;
import java.io.DataOutputStream;
import java.io.FileOutputStream;
import java.io.FileReader;
import java.io.BufferedOutputStream;

import org.phantogram.NativeBridge;

/**
 * Desktop JVM test driver (run by android/tests/jvm.rs): loads the host build of the Android
 * bridge, replays a sensor log through JNI exactly as the app's sensor listener would (Sensor
 * types, nanosecond time stamps), draws offscreen every 100 ms of log time, and writes the
 * last frame. Also checks that errors arrive as the documented Java exceptions.
 *
 * Usage: ReplayThroughJni LIBRARY LOG OUT WIDTH HEIGHT
 */
public final class ReplayThroughJni {
    static void expect(Class<? extends Throwable> type, String fragment, Runnable call) {
        try {
            call.run();
        } catch (Throwable t) {
            if (!type.isInstance(t) || t.getMessage() == null || !t.getMessage().contains(fragment)) {
                throw new AssertionError("expected " + type.getName() + " containing '" + fragment + "', got " + t, t);
            }
            System.out.println("ok: " + type.getSimpleName() + ": " + t.getMessage());
            return;
        }
        throw new AssertionError("expected " + type.getName() + " containing '" + fragment + "', nothing thrown");
    }

    public static void main(String[] args) throws Exception {
        NativeBridge.load(args[0]);
        String log = args[1];
        String out = args[2];
        int width = Integer.parseInt(args[3]);
        int height = Integer.parseInt(args[4]);

        expect(IllegalArgumentException.class, "sepia",
                () -> NativeBridge.nativeCreate(null, null, 1080, 2400, 420f, 420f, 0, "sepia", null, null, null, null));
        expect(IllegalArgumentException.class, "rotation",
                () -> NativeBridge.nativeCreate(null, null, 1080, 2400, 420f, 420f, 7, null, null, null, null, null));
        expect(IllegalStateException.class, "destroyed", () -> NativeBridge.nativeDrawFrame(0, -1));
        expect(IllegalStateException.class, "destroyed", () -> NativeBridge.nativeSetSensorRanges(0, 78.4532f, 34.9f));

        // Camera intrinsics from Camera2's characteristics, derived in Rust: a 4:3 sensor of
        // 4032 x 3024 active pixels (1 um, 4.2 mm lens) seen through a 16:9 stream of 1280 x 720
        // keeps the full width and 2268 rows from row 378 (core/src/camera/android.rs).
        float[] k = NativeBridge.nativeCameraIntrinsics(new int[] {0, 0, 4032, 3024}, null,
                new int[] {4032, 3024}, new float[] {4.032f, 3.024f}, 4.2f, null, 1280, 720);
        float s = 1280f / 4032f;
        float[] want = {4200f * s, 4200f * s, 2016f * s, (1512f - 378f) * s};
        for (int i = 0; i < 4; i++) {
            if (Math.abs(k[i] - want[i]) > 1e-2f) {
                throw new AssertionError("intrinsics " + java.util.Arrays.toString(k) + ", want "
                        + java.util.Arrays.toString(want));
            }
        }
        float[] calibrated = NativeBridge.nativeCameraIntrinsics(new int[] {0, 0, 4032, 3024}, null, null, null,
                Float.NaN, new float[] {4150f, 4160f, 2030f, 1500f, 0f}, 2016, 1512);
        if (calibrated[0] != 2075f || calibrated[3] != 750f) {
            throw new AssertionError("calibrated intrinsics " + java.util.Arrays.toString(calibrated));
        }
        expect(IllegalArgumentException.class, "focal length",
                () -> NativeBridge.nativeCameraIntrinsics(new int[] {0, 0, 4032, 3024}, null, null, null,
                        Float.NaN, null, 640, 480));
        expect(IllegalArgumentException.class, "activeArray must have 4 elements",
                () -> NativeBridge.nativeCameraIntrinsics(new int[] {0, 0, 4032}, null, null, null, 4.2f,
                        null, 640, 480));
        expect(IllegalArgumentException.class, "activeArray is null",
                () -> NativeBridge.nativeCameraIntrinsics(null, null, null, null, 4.2f, null, 640, 480));

        long h = NativeBridge.nativeCreate(null, null, 1080, 2400, 420f, 420f, 0, "dubois", null, null, null, null);
        try {
            expect(IllegalStateException.class, "no offscreen frame", () -> NativeBridge.nativeReadFrame(h));
            expect(UnsupportedOperationException.class, "only on Android",
                    () -> NativeBridge.nativeSurfaceCreated(h, new Object(), 100, 100));
            expect(IllegalArgumentException.class, "unknown anaglyph method",
                    () -> NativeBridge.nativeSetAnaglyph(h, "sepia"));
            if (NativeBridge.nativeDrawFrame(h, -1)) {
                throw new AssertionError("drawing without a surface must be a skipped frame");
            }
            // A +-8 g accelerometer and a +-2000 deg/s gyroscope, as a Nexus 5 declares them.
            NativeBridge.nativeSetSensorRanges(h, 78.4532f, 34.906586f);
            NativeBridge.nativeResumeOffscreen(h, width, height);

            final long stepNs = 100_000_000L;
            long next = Long.MIN_VALUE;
            long last = 0;
            int frames = 0;
            int rejected = 0;
            try (BufferedReader r = new BufferedReader(new FileReader(log))) {
                String line;
                while ((line = r.readLine()) != null) {
                    String[] f = line.trim().split("\\s+");
                    int type;
                    switch (f[0]) {
                        case "acc": type = 1; break;   // Sensor.TYPE_ACCELEROMETER
                        case "mag": type = 2; break;   // Sensor.TYPE_MAGNETIC_FIELD
                        case "gyr": type = 4; break;   // Sensor.TYPE_GYROSCOPE
                        default: continue;
                    }
                    long t = Long.parseLong(f[1]);
                    if (next == Long.MIN_VALUE) {
                        next = t + stepNs;
                    }
                    while (t > next) {
                        if (NativeBridge.nativeDrawFrame(h, next)) {
                            frames++;
                        }
                        next += stepNs;
                    }
                    boolean ok = NativeBridge.nativePushSensor(h, type, t,
                            Float.parseFloat(f[2]), Float.parseFloat(f[3]), Float.parseFloat(f[4]), Float.NaN);
                    if (!ok) {
                        rejected++;
                    }
                    last = t;
                }
            }
            if (!NativeBridge.nativeDrawFrame(h, last)) {
                throw new AssertionError("the last frame was skipped");
            }
            frames++;
            int[] frame = NativeBridge.nativeReadFrame(h);
            if (frame[0] != width || frame[1] != height || frame.length != 2 + width * height) {
                throw new AssertionError("frame of " + frame[0] + "x" + frame[1] + ", " + frame.length + " ints");
            }
            try (DataOutputStream o = new DataOutputStream(new BufferedOutputStream(new FileOutputStream(out)))) {
                for (int i = 2; i < frame.length; i++) {
                    o.writeInt(frame[i]);
                }
            }
            final long end = last;
            // Every other native method once, so that a declaration out of step with the library
            // fails here (the JVM links native methods at their first call).
            if (NativeBridge.nativeTouch(h, NativeBridge.TOUCH_DOWN, 0, 10f, 10f, last) != NativeBridge.GESTURE_NONE
                    || NativeBridge.nativeTouch(h, NativeBridge.TOUCH_UP, 0, 10f, 10f, last + 50_000_000L) != NativeBridge.GESTURE_NONE) {
                throw new AssertionError("a single tap is no gesture");
            }
            expect(IllegalArgumentException.class, "touch phase", () -> NativeBridge.nativeTouch(h, 9, 0, 0f, 0f, end));
            NativeBridge.nativeSetDisplay(h, 1080, 2400, 420f, 420f, 0);
            java.nio.ByteBuffer luma = java.nio.ByteBuffer.allocateDirect(64 * 48);
            // CameraX's usual chroma: two views of one interleaved plane, pixel stride 2.
            java.nio.ByteBuffer cb = java.nio.ByteBuffer.allocateDirect(64 * 24 - 1);
            java.nio.ByteBuffer cr = java.nio.ByteBuffer.allocateDirect(64 * 24 - 1);
            if (NativeBridge.nativeCameraFrame(h, NativeBridge.CAMERA_FRONT, luma, 64, 48, 64, null, null, 0, 0, 270, 50f, 50f, 32f, 24f, last)) {
                throw new AssertionError("face tracking is off: the frame must not be taken");
            }
            if (NativeBridge.nativeCameraFrame(h, NativeBridge.CAMERA_FRONT, luma, 64, 48, 64, cb, cr, 64, 2, 270, 50f, 50f, 32f, 24f, last)) {
                throw new AssertionError("face tracking is off: the colour frame must not be taken");
            }
            expect(IllegalArgumentException.class, "camera frame",
                    () -> NativeBridge.nativeCameraFrame(h, NativeBridge.CAMERA_FRONT, luma, 64, 48, 64, null, null, 0, 0, 45, 50f, 50f, 32f, 24f, end));
            expect(IllegalArgumentException.class, "Cb row stride",
                    () -> NativeBridge.nativeCameraFrame(h, NativeBridge.CAMERA_FRONT, luma, 64, 48, 64, cb, cr, 64, 4, 270, 50f, 50f, 32f, 24f, end));
            expect(IllegalArgumentException.class, "chroma planes",
                    () -> NativeBridge.nativeCameraFrame(h, NativeBridge.CAMERA_FRONT, luma, 64, 48, 64, cb, null, 64, 2, 270, 50f, 50f, 32f, 24f, end));
            // A heap buffer has no address to read (was a "Rust error" RuntimeException).
            expect(IllegalArgumentException.class, "not a direct buffer",
                    () -> NativeBridge.nativeCameraFrame(h, NativeBridge.CAMERA_FRONT, java.nio.ByteBuffer.allocate(64 * 48), 64, 48, 64, null, null, 0, 0,
                            270, 50f, 50f, 32f, 24f, end));
            // The room light is off in this engine, but an exposure is taken (for when it is on);
            // an unknown one is not.
            if (!NativeBridge.nativeCameraExposure(h, NativeBridge.CAMERA_FRONT, last, 10_000_000L, 200, 2.2f)
                    || !NativeBridge.nativeCameraExposure(h, NativeBridge.CAMERA_REAR, last, 10_000_000L, 200, Float.NaN)
                    || NativeBridge.nativeCameraExposure(h, NativeBridge.CAMERA_FRONT, last, 0L, 200, 2.2f)) {
                throw new AssertionError("camera exposure");
            }
            // The rear camera feeds the room light alone, which is off here.
            if (NativeBridge.nativeCameraFrame(h, NativeBridge.CAMERA_REAR, luma, 64, 48, 64, cb, cr, 64, 2, 90, 50f, 50f,
                    32f, 24f, last)) {
                throw new AssertionError("the room light is off: the rear frame must not be taken");
            }
            expect(IllegalArgumentException.class, "camera must be 0",
                    () -> NativeBridge.nativeCameraFrame(h, 2, luma, 64, 48, 64, null, null, 0, 0, 90, 50f, 50f, 32f, 24f, end));
            expect(IllegalArgumentException.class, "camera must be 0",
                    () -> NativeBridge.nativeCameraExposure(h, -1, end, 10_000_000L, 200, 2f));
            NativeBridge.nativeSurfaceChanged(h, width / 2, height / 2);
            NativeBridge.nativeSurfaceDestroyed(h);
            if (NativeBridge.nativeDrawFrame(h, last)) {
                throw new AssertionError("drawing after surfaceDestroyed must be a skipped frame");
            }
            if (NativeBridge.nativeCalibrationWarning(h) != null) {
                throw new AssertionError("no calibration file, yet a calibration warning");
            }
            long[] stats = NativeBridge.nativeStats(h);
            System.out.println("frames " + frames + " drawn " + stats[0] + " skipped " + stats[1]
                    + " accepted " + stats[4] + " rejected " + stats[5] + " (driver saw " + rejected + ")");
        } finally {
            NativeBridge.nativeDestroy(h);
        }
        // A damaged calibration file: the engine starts with the defaults and says why.
        java.nio.file.Path damaged = java.nio.file.Paths.get(out + ".calibration.txt");
        java.nio.file.Files.write(damaged, "not a calibration\n".getBytes(java.nio.charset.StandardCharsets.UTF_8));
        long c = NativeBridge.nativeCreate(null, null, 1080, 2400, 420f, 420f, 0, null, damaged.toString(), null,
                null, null);
        try {
            String warning = NativeBridge.nativeCalibrationWarning(c);
            if (warning == null || !warning.contains(damaged.getFileName().toString())) {
                throw new AssertionError("calibration warning for a damaged file: " + warning);
            }
            System.out.println("ok: damaged calibration file: " + warning);
        } finally {
            NativeBridge.nativeDestroy(c);
        }

        // The artifact library as the Kotlin shell uses it: start on a saved id, open a file,
        // choose another, share the view. Loads run in the background: draw until they end.
        expect(IllegalArgumentException.class, "not an artifact id",
                () -> NativeBridge.nativeCreate(null, null, 1080, 2400, 420f, 420f, 0, null, null, null, null,
                        "medal"));
        String library = out + ".library";
        long a = NativeBridge.nativeCreate(null, null, 1080, 2400, 420f, 420f, 0, "mono", null, library, null,
                "builtin:medal");
        try {
            if (!"builtin:medal".equals(NativeBridge.nativeCurrentArtifact(a))) {
                throw new AssertionError("on screen: " + NativeBridge.nativeCurrentArtifact(a));
            }
            NativeBridge.nativeResumeOffscreen(a, 90, 200);
            expect(IllegalArgumentException.class, "empty", () -> NativeBridge.nativeImportArtifact(a, "x.glb",
                    new byte[0]));
            expect(IllegalArgumentException.class, "not open", () -> NativeBridge.nativeImportArtifactFd(a, "x.glb",
                    -1));
            NativeBridge.nativeImportArtifact(a, "damaged.glb",
                    "glTF\u0002\u0000\u0000\u0000 not a model".getBytes(java.nio.charset.StandardCharsets.ISO_8859_1));
            float[] state = NativeBridge.nativeLoadingState(a);
            for (int i = 0; i < 100000 && state[0] == 1f; i++) {
                NativeBridge.nativeDrawFrame(a, -1);
                state = NativeBridge.nativeLoadingState(a);
            }
            if (state[0] != 2f) {
                throw new AssertionError("a damaged file ended in loading state " + state[0]);
            }
            NativeBridge.nativeSelectArtifact(a, "builtin:tablet");
            for (int i = 0; i < 100000 && NativeBridge.nativeLoadingState(a)[0] != 0f; i++) {
                NativeBridge.nativeDrawFrame(a, -1);
            }
            NativeBridge.nativeDrawFrame(a, -1);
            if (!"builtin:tablet".equals(NativeBridge.nativeCurrentArtifact(a))) {
                throw new AssertionError("after selecting the tablet: " + NativeBridge.nativeCurrentArtifact(a));
            }
            NativeBridge.nativeOpenMenu(a);
            NativeBridge.nativeSetTextScale(a, 1.3f);
            expect(IllegalArgumentException.class, "text scale", () -> NativeBridge.nativeSetTextScale(a, Float.NaN));
            // The core explains the camera before anything is asked of the system.
            NativeBridge.nativeCameraPermissionNeeded(a);
            NativeBridge.nativeDrawFrame(a, -1);
            if (NativeBridge.nativeTakeShellRequest(a) != NativeBridge.REQUEST_NONE) {
                throw new AssertionError("a shell request before anything was asked");
            }
            byte[] png = NativeBridge.nativeSnapshotPng(a, 1);
            int pngWidth = java.nio.ByteBuffer.wrap(png, 16, 4).getInt();
            if (png[1] != 'P' || pngWidth != 180) {
                throw new AssertionError("side-by-side PNG " + pngWidth + " wide");
            }
            expect(IllegalArgumentException.class, "snapshot kind", () -> NativeBridge.nativeSnapshotPng(a, 5));
            System.out.println("ok: library: damaged import reported, tablet shown, side-by-side PNG "
                    + png.length + " bytes");
            // What TalkBack is given: every node named and placed; activating one moves the
            // screens on (the generation tells the shell to read them again).
            NativeBridge.nativeDrawFrame(a, -1);
            NativeBridge.AccessibilityNode[] nodes = NativeBridge.nativeAccessibilityNodes(a);
            long generation = NativeBridge.nativeAccessibilityGeneration(a);
            NativeBridge.AccessibilityNode done = null;
            StringBuilder read = new StringBuilder();
            for (NativeBridge.AccessibilityNode n : nodes) {
                read.append(n.role).append(':').append(n.label).append(n.has(NativeBridge.AccessibilityNode.FLAG_CHECKED)
                        ? " (on)" : "").append("; ");
                if (n.label.isEmpty() || !(n.right > n.left) || !(n.bottom > n.top) || n.id <= 0) {
                    throw new AssertionError("a node without a name or a place: " + n.label + " " + n.id);
                }
                if (n.role == NativeBridge.AccessibilityNode.ROLE_BUTTON
                        && n.has(NativeBridge.AccessibilityNode.FLAG_CLICKABLE) && n.label.equals("Done")) {
                    done = n;
                }
            }
            System.out.println("read: " + read);
            if (done == null) {
                throw new AssertionError("no way to close the menu: " + read);
            }
            if (NativeBridge.nativeAccessibilityClick(a, 99999) || NativeBridge.nativeAccessibilityAdjust(a, done.id, 1)) {
                throw new AssertionError("an unknown node or a button's step was taken");
            }
            if (!NativeBridge.nativeAccessibilityClick(a, done.id)) {
                throw new AssertionError("activating '" + done.label + "' was refused");
            }
            NativeBridge.nativeDrawFrame(a, -1);
            NativeBridge.nativeDrawFrame(a, -1);
            if (NativeBridge.nativeAccessibilityGeneration(a) == generation) {
                throw new AssertionError("activating '" + done.label + "' changed nothing");
            }
            System.out.println("ok: accessibility: " + nodes.length + " nodes read, '" + done.label
                    + "' activated, " + NativeBridge.nativeAccessibilityNodes(a).length + " nodes after");
        } finally {
            NativeBridge.nativeDestroy(a);
        }
        System.out.println("done");
    }
}
