import java.nio.ByteBuffer;
import java.util.Random;
import org.phantogram.NativeBridge;

/**
 * Random call sequences through the JNI bridge (android/tests/jvm.rs runs it): every native
 * method, in a random order, with random arguments — valid, out of range, NaN, null, empty,
 * damaged — on one live engine (and the destroyed handle 0). Each call must return or throw one
 * of the documented exceptions; a Rust panic or a JNI error ("Rust panic", "Rust error") or any
 * other throwable fails, and so does the JVM dying.
 *
 * Not random, by the bridge's contract: handles are the live one or 0 (any other value is
 * undefined behaviour, as with any C handle), descriptors are never open ones (the library would
 * own and close it, and the JVM's own files are open), and nativeDestroy ends the run.
 *
 * Usage: RandomCalls LIBRARY SEED CALLS LIBRARY_DIR, or RandomCalls LIBRARY bytes:FILE 0 LIBRARY_DIR
 * to make the calls fuzz() makes from a file's bytes (as the fuzz target does, checked by the
 * JVM test).
 *
 * The same calls are libFuzzer's JNI target (fuzz/fuzz_targets/jni.rs, in the fuzzer's own
 * process): start() makes the live engine once, fuzz() draws its calls from the fuzzer's bytes
 * instead of a seeded Random, and nativeMethods() names each native method with its JNI
 * descriptor for RegisterNatives.
 */
public final class RandomCalls {
    private static Random random;
    /** -Dphantogram.trace=true: each call and its time on stderr (to see what an input does). */
    private static final boolean TRACE = Boolean.getBoolean("phantogram.trace");
    /**
     * What a fuzz input may still spend on rendering: a frame costs 1, a snapshot or a second
     * engine 8, and each input starts with 24; a call over the budget is skipped. The engine
     * persists between inputs, so no state is out of reach, and an input stays well inside
     * libFuzzer's 10-s timeout: with three fuzzers on two cores a frame took up to 0.23 s and a
     * snapshot at the full panel (after the surface is gone) up to 2.6 s, and the inputs with
     * five of those timed out. Unlimited in the seeded runs.
     */
    private static long renderBudget = Long.MAX_VALUE;

    private static boolean spend(long cost) {
        if (renderBudget < cost) return false;
        renderBudget -= cost;
        return true;
    }
    private static long calls = 0;
    private static long thrown = 0;
    /** The last calls made, for the report of a failure. */
    private static final java.util.ArrayDeque<String> recent = new java.util.ArrayDeque<>();

    private static void note(String what) {
        if (recent.size() == 40) recent.removeFirst();
        recent.addLast(what);
    }

    private static float anyFloat() {
        switch (random.nextInt(8)) {
            case 0: return Float.NaN;
            case 1: return random.nextBoolean() ? Float.POSITIVE_INFINITY : Float.NEGATIVE_INFINITY;
            case 2: return 0f;
            case 3: return (random.nextFloat() - 0.5f) * 1e30f;
            default: return (random.nextFloat() - 0.5f) * 40f;
        }
    }

    private static int anyInt(int typicalMax) {
        switch (random.nextInt(6)) {
            case 0: return -1 - random.nextInt(1000);
            case 1: return random.nextBoolean() ? Integer.MAX_VALUE : Integer.MIN_VALUE;
            default: return random.nextInt(typicalMax + 1);
        }
    }

    private static long anyTime() {
        switch (random.nextInt(6)) {
            case 0: return Long.MIN_VALUE;
            case 1: return Long.MAX_VALUE;
            case 2: return -random.nextInt(1_000_000);
            default: return (long) random.nextInt(600) * 16_666_667L;
        }
    }

    private static String anyString(String... typical) {
        switch (random.nextInt(5)) {
            case 0: return null;
            case 1: return "";
            case 2: {
                StringBuilder s = new StringBuilder();
                int n = random.nextInt(40);
                // Any UTF-16 unit half the time, unpaired surrogates included (a document's
                // display name can hold them; the bridge reads Java's modified UTF-8).
                boolean any = random.nextBoolean();
                for (int i = 0; i < n; i++) s.append((char) random.nextInt(any ? 0x10000 : 0x3000));
                return s.toString();
            }
            default: return typical.length == 0 ? "x" : typical[random.nextInt(typical.length)];
        }
    }

    private static byte[] anyBytes(int max) {
        byte[] b = new byte[random.nextInt(max + 1)];
        random.nextBytes(b);
        if (b.length >= 12 && random.nextBoolean()) {
            // A GLB header, so that the loader gets past the magic now and then.
            b[0] = 'g'; b[1] = 'l'; b[2] = 'T'; b[3] = 'F'; b[4] = 2; b[5] = 0; b[6] = 0; b[7] = 0;
        }
        return b;
    }

    private static int[] anyInts(int maxLen, int typicalMax) {
        if (random.nextInt(6) == 0) return null;
        int[] a = new int[random.nextInt(maxLen + 1)];
        for (int i = 0; i < a.length; i++) a[i] = anyInt(typicalMax);
        return a;
    }

    private static float[] anyFloats(int maxLen) {
        if (random.nextInt(6) == 0) return null;
        float[] a = new float[random.nextInt(maxLen + 1)];
        for (int i = 0; i < a.length; i++) a[i] = anyFloat();
        return a;
    }

    private static ByteBuffer anyBuffer(int max) {
        int r = random.nextInt(8);
        if (r == 0) return null;
        // Mostly direct (what the camera gives), sometimes a heap buffer (which has no address).
        ByteBuffer b = r == 1 ? ByteBuffer.allocate(random.nextInt(max + 1)) : ByteBuffer.allocateDirect(random.nextInt(max + 1));
        return b;
    }

    /** One random call on handle h. */
    private static void call(long h, String libraryDir) {
        int which = random.nextInt(33);
        note("case " + which + (h == 0 ? " (handle 0)" : ""));
        switch (which) {
            case 0: NativeBridge.nativePushSensor(h, random.nextInt(40) - 2, anyTime(), anyFloat(), anyFloat(), anyFloat(), anyFloat()); break;
            case 1: {
                int w = anyInt(64), hh = anyInt(48);
                NativeBridge.nativeCameraFrame(h, anyInt(3), anyBuffer(4096), w, hh, anyInt(80), anyBuffer(2048), anyBuffer(2048),
                        anyInt(80), anyInt(3), anyInt(360), anyFloat(), anyFloat(), anyFloat(), anyFloat(), anyTime());
                break;
            }
            case 2: NativeBridge.nativeCameraExposure(h, anyInt(3), anyTime(), anyTime(), anyInt(6400), anyFloat()); break;
            case 3: NativeBridge.nativeCameraIntrinsics(anyInts(5, 4000), anyInts(5, 4000), anyInts(3, 4000), anyFloats(3),
                    anyFloat(), anyFloats(6), anyInt(640), anyInt(480)); break;
            case 4: NativeBridge.nativeTouch(h, anyInt(4), anyInt(5), anyFloat(), anyFloat(), anyTime()); break;
            case 5: NativeBridge.nativeSurfaceCreated(h, random.nextBoolean() ? null : "not a surface", anyInt(400), anyInt(400)); break;
            case 6: { int w = anyInt(200), hh = anyInt(300); note("resumeOffscreen " + w + "x" + hh); NativeBridge.nativeResumeOffscreen(h, w, hh); break; }
            case 7: { int w = anyInt(200), hh = anyInt(300); note("surfaceChanged " + w + "x" + hh); NativeBridge.nativeSurfaceChanged(h, w, hh); break; }
            case 8: NativeBridge.nativeSurfaceDestroyed(h); break;
            case 9: {
                int pw = anyInt(1440), ph = anyInt(3200), rot = anyInt(4);
                float xd = anyFloat(), yd = anyFloat();
                note("setDisplay " + pw + "x" + ph + " " + xd + " " + yd + " rot " + rot);
                NativeBridge.nativeSetDisplay(h, pw, ph, xd, yd, rot);
                break;
            }
            case 10: NativeBridge.nativeSetAnaglyph(h, anyString("dubois", "mono", "half-color", "sepia")); break;
            case 11: NativeBridge.nativeSetSensorRanges(h, anyFloat(), anyFloat()); break;
            case 12: if (spend(1)) NativeBridge.nativeDrawFrame(h, random.nextBoolean() ? -1 : anyTime()); break;
            case 13: NativeBridge.nativeReadFrame(h); break;
            case 14: NativeBridge.nativeStats(h); break;
            case 15: NativeBridge.nativeCalibrationWarning(h); break;
            case 16: { float scale = anyFloat(); note("setTextScale " + scale); NativeBridge.nativeSetTextScale(h, scale); break; }
            case 17: NativeBridge.nativeCameraPermissionNeeded(h); break;
            case 18: NativeBridge.nativeImportArtifact(h, anyString("a.glb", "b.gltf", "c.zip", "../../x.glb"), random.nextInt(8) == 0 ? null : anyBytes(2048)); break;
            // Never an open descriptor: the library would own and close it.
            case 19: NativeBridge.nativeImportArtifactFd(h, anyString("a.glb"), random.nextBoolean() ? -1 : 1_000_000 + random.nextInt(1000)); break;
            case 20: NativeBridge.nativeSelectArtifact(h, anyString("builtin:medal", "builtin:tablet", "builtin:diorama", "builtin:amphora", "imported:nothing", "bundled:none")); break;
            case 21: NativeBridge.nativeCurrentArtifact(h); break;
            case 22: NativeBridge.nativeOpenMenu(h); break;
            case 23: NativeBridge.nativeTakeShellRequest(h); break;
            case 24: NativeBridge.nativeLoadingState(h); break;
            case 25: if (spend(8)) NativeBridge.nativeSnapshotPng(h, anyInt(2)); break;
            case 26: NativeBridge.nativeAccessibilityNodes(h); break;
            case 27: NativeBridge.nativeAccessibilityGeneration(h); break;
            case 28: {
                // Mostly a node on screen now, so that activations open pages.
                NativeBridge.AccessibilityNode[] nodes = h == 0 ? null : NativeBridge.nativeAccessibilityNodes(h);
                int id = nodes != null && nodes.length > 0 && random.nextInt(4) != 0 ? nodes[random.nextInt(nodes.length)].id : anyInt(100);
                NativeBridge.nativeAccessibilityClick(h, id);
                break;
            }
            case 29: NativeBridge.nativeAccessibilityAdjust(h, anyInt(100), anyInt(10) - 5); break;
            case 30: {
                // Taps where the screens are: a tap down and up at a random place.
                float x = random.nextFloat() * 90, y = random.nextFloat() * 200;
                long t = (long) random.nextInt(600) * 16_666_667L;
                NativeBridge.nativeTouch(h, NativeBridge.TOUCH_DOWN, 0, x, y, t);
                NativeBridge.nativeTouch(h, NativeBridge.TOUCH_UP, 0, x, y, t + 50_000_000L);
                break;
            }
            case 31: {
                // Rarely: another engine with random settings, destroyed at once.
                if (random.nextInt(20) != 0 || !spend(8)) break;
                long other = NativeBridge.nativeCreate(anyString("/nonexistent.glb"), null, anyInt(1440), anyInt(3200), anyFloat(),
                        anyFloat(), anyInt(4), anyString("dubois", "mono"), null, random.nextBoolean() ? null : libraryDir, null,
                        anyString("builtin:medal"));
                NativeBridge.nativeDestroy(other);
                break;
            }
            default: NativeBridge.nativeDestroy(0); break;
        }
    }

    /**
     * One call on the live engine h (now and then on handle 0 instead); an undocumented exception
     * (a Rust panic, a JNI failure, any other throwable) becomes an AssertionError naming the
     * calls before it.
     */
    private static void checkedCall(long h, String libraryDir, String where) {
        long handle = random.nextInt(30) == 0 ? 0 : h;
        calls++;
        long started = System.nanoTime();
        try {
            call(handle, libraryDir);
        } catch (IllegalArgumentException | IllegalStateException | UnsupportedOperationException e) {
            thrown++;
        } catch (RuntimeException e) {
            String m = String.valueOf(e.getMessage());
            // A panic or a JNI failure is a bug; a load or GPU failure is documented.
            if (e.getClass() != RuntimeException.class || m.startsWith("Rust panic") || m.startsWith("Rust error")) {
                throw new AssertionError(where + ": " + e + "\nthe calls before it: " + String.join("; ", recent), e);
            }
            thrown++;
        } finally {
            if (TRACE) {
                System.err.println(where + ": " + recent.peekLast() + ", " + (System.nanoTime() - started) / 1_000_000 + " ms");
            }
        }
    }

    /** The live engine every call drives, shown offscreen (what a shell does first). */
    public static long start(String libraryDir) {
        long h = NativeBridge.nativeCreate(null, null, 1080, 2400, 420f, 420f, 0, "dubois", null, libraryDir, null, null);
        NativeBridge.nativeResumeOffscreen(h, 90, 200);
        return h;
    }

    /** libFuzzer's input: calls on h drawn from its bytes until they run out. */
    public static void fuzz(long h, byte[] data, String libraryDir) {
        BytesRandom bytes = new BytesRandom(data);
        random = bytes;
        recent.clear();
        renderBudget = 24;
        while (bytes.remaining() > 0) {
            checkedCall(h, libraryDir, "fuzz input call " + calls);
        }
    }

    /**
     * "name descriptor" of each native method of NativeBridge, e.g. "nativeDestroy (J)V": what
     * RegisterNatives needs, read from the class itself so that it cannot drift from it.
     */
    public static String[] nativeMethods() {
        java.util.ArrayList<String> found = new java.util.ArrayList<>();
        for (java.lang.reflect.Method m : NativeBridge.class.getDeclaredMethods()) {
            if (!java.lang.reflect.Modifier.isNative(m.getModifiers())) continue;
            StringBuilder d = new StringBuilder("(");
            for (Class<?> p : m.getParameterTypes()) d.append(descriptor(p));
            d.append(')').append(descriptor(m.getReturnType()));
            found.add(m.getName() + " " + d);
        }
        return found.toArray(new String[0]);
    }

    private static String descriptor(Class<?> c) {
        if (c.isArray()) return "[" + descriptor(c.getComponentType());
        if (c == void.class) return "V";
        if (c == boolean.class) return "Z";
        if (c == byte.class) return "B";
        if (c == char.class) return "C";
        if (c == short.class) return "S";
        if (c == int.class) return "I";
        if (c == long.class) return "J";
        if (c == float.class) return "F";
        if (c == double.class) return "D";
        return "L" + c.getName().replace('.', '/') + ";";
    }

    /**
     * A Random whose bits are the fuzzer's bytes, in order (a draw of n bits takes ceil(n / 8)
     * bytes), then zeros: every draw of nextInt(bound) then ends (zero is always in range), so a
     * call that starts near the end still finishes.
     */
    static final class BytesRandom extends Random {
        private final byte[] data;
        private int at = 0;

        BytesRandom(byte[] data) {
            this.data = data;
        }

        int remaining() {
            return data.length - at;
        }

        @Override
        protected int next(int bits) {
            int v = 0;
            for (int i = 0; i < (bits + 7) / 8; i++) {
                v = (v << 8) | (at < data.length ? data[at++] & 0xff : 0);
            }
            return bits == 32 ? v : v & ((1 << bits) - 1);
        }
    }

    public static void main(String[] args) throws Exception {
        NativeBridge.load(args[0]);
        String libraryDir = args[3];
        if (args[1].startsWith("bytes:")) {
            byte[] data = java.nio.file.Files.readAllBytes(java.nio.file.Paths.get(args[1].substring(6)));
            long h = start(libraryDir);
            fuzz(h, data, libraryDir);
            NativeBridge.nativeDestroy(h);
            System.out.println("calls from " + data.length + " bytes: " + calls + " calls, " + thrown + " documented exceptions");
            System.out.println("done");
            return;
        }
        long seed = Long.parseLong(args[1]);
        long total = Long.parseLong(args[2]);
        random = new Random(seed);
        long h = start(libraryDir);
        for (long i = 0; i < total; i++) {
            checkedCall(h, libraryDir, "call " + i + " (seed " + seed + ")");
        }
        NativeBridge.nativeDestroy(h);
        System.out.println("random calls: seed " + seed + ", " + calls + " calls, " + thrown + " documented exceptions");
        System.out.println("done");
    }
}
