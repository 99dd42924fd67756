package org.phantogram

import android.Manifest
import android.content.Context
import android.content.Intent
import android.content.SharedPreferences
import android.content.pm.PackageManager
import android.content.res.Configuration
import android.hardware.SensorManager
import android.net.Uri
import android.os.Build
import android.os.Bundle
import android.provider.OpenableColumns
import android.util.DisplayMetrics
import android.util.Log
import android.view.MotionEvent
import android.view.Surface
import android.view.SurfaceHolder
import android.view.SurfaceView
import android.view.WindowInsets
import android.view.WindowInsetsController
import android.view.WindowManager
import android.widget.Toast
import androidx.activity.ComponentActivity
import androidx.activity.result.contract.ActivityResultContracts
import androidx.core.content.FileProvider
import java.io.File

/**
 * The whole Android shell: one full-screen SurfaceView. It forwards the surface (holder
 * callbacks), sensors, camera frames, touches, lifecycle and display metrics to the Rust
 * core through NativeBridge; everything else happens there.
 *
 * Lifecycle: onResume starts sensors and frames, onPause stops them; the surface follows the
 * holder callbacks (its loss never loses the GPU device); rotation is handled in place
 * (configChanges), so the engine survives it.
 */
class MainActivity : ComponentActivity(), SurfaceHolder.Callback {
    private val render = RenderLoop(
        onError = { t -> Log.e(TAG, "phantogram", t) },
        // The core's menu asked for a file: the system's document picker, on the UI thread.
        onOpenFile = { runOnUiThread { openDocument.launch(MODEL_TYPES) } },
        // The core's camera page said why and the user wants the camera: the system's request.
        onCameraPermission = { runOnUiThread { askCamera.launch(Manifest.permission.CAMERA) } },
        onShare = { png, pair -> runOnUiThread { share(png, pair) } },
        // The room light's camera wish, kept for when the camera starts (UI thread).
        onRearCamera = { on -> runOnUiThread { wantRear = on; camera?.setRear(on) } }
    )
    private var wantRear = false
    private lateinit var sensors: SensorForwarder
    private var camera: CameraForwarder? = null
    private var surfaceReady = false

    private val askCamera = registerForActivityResult(ActivityResultContracts.RequestPermission()) { granted ->
        if (granted) startCamera() else Toast.makeText(this, R.string.tilt_only, Toast.LENGTH_LONG).show()
    }

    private val openDocument = registerForActivityResult(ActivityResultContracts.OpenDocument()) { uri: Uri? ->
        if (uri != null) import(uri)
    }

    override fun onCreate(savedInstanceState: Bundle?) {
        super.onCreate(savedInstanceState)
        NativeBridge.load(null)
        window.addFlags(WindowManager.LayoutParams.FLAG_KEEP_SCREEN_ON)
        immersive()
        val view = SurfaceView(this)
        view.holder.addCallback(this)
        setContentView(view)
        // TalkBack reads the core's screens as virtual views of the surface.
        val screenReader = ScreenReader(view) { render.engine }
        screenReader.attach()
        render.onAccessibilityChanged = { screenReader.changed() }
        val prefs = getSharedPreferences(PREFS, Context.MODE_PRIVATE)
        refreshBundledAssets(prefs)
        render.create(extractFaceModels(), panel(), "dubois", File(filesDir, "calibration.txt").path,
            File(filesDir, "artifacts").path, File(filesDir, BUNDLED).path, prefs.getString(PREF_ARTIFACT, null))
        render.setTextScale(resources.configuration.fontScale)
        intent?.let { openedWith(it) }
        sensors = SensorForwarder(getSystemService(SensorManager::class.java)) { render.engine }
        if (checkSelfPermission(Manifest.permission.CAMERA) == PackageManager.PERMISSION_GRANTED) {
            startCamera()
        } else {
            // Not asked out of the blue: the core's camera page says what the camera is for and
            // asks back (onCameraPermission) only if the user wants it.
            render.cameraPermissionNeeded()
        }
    }

    /** A snapshot of the view to the system's share sheet: written to the app's cache and
     *  handed over through its FileProvider (read permission for the chosen app only). */
    private fun share(png: ByteArray, pair: Boolean) {
        try {
            val dir = File(cacheDir, "shared")
            dir.mkdirs()
            val file = File(dir, if (pair) "phantogram-stereo-pair.png" else "phantogram-anaglyph.png")
            file.writeBytes(png)
            val uri = FileProvider.getUriForFile(this, "$packageName.share", file)
            val send = Intent(Intent.ACTION_SEND)
                .setType("image/png")
                .putExtra(Intent.EXTRA_STREAM, uri)
                .addFlags(Intent.FLAG_GRANT_READ_URI_PERMISSION)
            startActivity(Intent.createChooser(send, getString(R.string.share_title)))
        } catch (e: Exception) {
            Log.e(TAG, "share", e)
            Toast.makeText(this, R.string.cannot_share, Toast.LENGTH_LONG).show()
        }
    }

    override fun onResume() {
        super.onResume()
        sensors.start()
        render.start()
    }

    override fun onNewIntent(intent: Intent) {
        super.onNewIntent(intent)
        openedWith(intent)
    }

    override fun onPause() {
        // The artifact on screen comes back at the next start.
        val prefs = getSharedPreferences(PREFS, Context.MODE_PRIVATE)
        render.reportArtifact { id -> if (id != null) prefs.edit().putString(PREF_ARTIFACT, id).apply() }
        render.stop()
        sensors.stop()
        super.onPause()
    }

    override fun onDestroy() {
        camera?.close()
        sensors.close()
        render.destroy()
        super.onDestroy()
    }

    override fun onConfigurationChanged(newConfig: Configuration) {
        super.onConfigurationChanged(newConfig)
        render.setDisplay(panel())
        render.setTextScale(newConfig.fontScale)
    }

    // Surface: created → (changed)+ → destroyed. Sizes are physical pixels, so the image is
    // drawn at the panel's full density.
    override fun surfaceCreated(holder: SurfaceHolder) {}

    override fun surfaceChanged(holder: SurfaceHolder, format: Int, width: Int, height: Int) {
        if (!surfaceReady) {
            surfaceReady = true
            render.surfaceCreated(holder.surface, width, height)
        } else {
            render.surfaceChanged(width, height)
        }
    }

    override fun surfaceDestroyed(holder: SurfaceHolder) {
        surfaceReady = false
        render.surfaceDestroyed()
    }

    override fun onTouchEvent(event: MotionEvent): Boolean {
        val e = render.engine
        if (e == 0L) return true
        val t = Clock.monotonicToSensorNs(event.eventTime * 1_000_000L)
        val phase = when (event.actionMasked) {
            MotionEvent.ACTION_DOWN, MotionEvent.ACTION_POINTER_DOWN -> NativeBridge.TOUCH_DOWN
            MotionEvent.ACTION_MOVE -> NativeBridge.TOUCH_MOVE
            MotionEvent.ACTION_UP, MotionEvent.ACTION_POINTER_UP -> NativeBridge.TOUCH_UP
            MotionEvent.ACTION_CANCEL -> NativeBridge.TOUCH_CANCEL
            else -> return true
        }
        if (phase == NativeBridge.TOUCH_MOVE || phase == NativeBridge.TOUCH_CANCEL) {
            for (i in 0 until event.pointerCount) {
                NativeBridge.nativeTouch(e, phase, event.getPointerId(i), event.getX(i), event.getY(i), t)
            }
        } else {
            val i = event.actionIndex
            NativeBridge.nativeTouch(e, phase, event.getPointerId(i), event.getX(i), event.getY(i), t)
        }
        return true
    }

    /** Full screen, bars hidden: the core's screen model is the whole panel, so the surface must
     *  be too (a surface inset by system bars would show the projection slightly stretched). */
    private fun immersive() {
        if (Build.VERSION.SDK_INT >= Build.VERSION_CODES.P) {
            window.attributes.layoutInDisplayCutoutMode =
                WindowManager.LayoutParams.LAYOUT_IN_DISPLAY_CUTOUT_MODE_SHORT_EDGES
        }
        if (Build.VERSION.SDK_INT >= Build.VERSION_CODES.R) {
            window.setDecorFitsSystemWindows(false)
            window.insetsController?.let {
                it.hide(WindowInsets.Type.systemBars())
                it.systemBarsBehavior = WindowInsetsController.BEHAVIOR_SHOW_TRANSIENT_BARS_BY_SWIPE
            }
        }
    }

    /** "Open with" (ACTION_VIEW) or a share (ACTION_SEND) of a model file. (The typed
     *  getParcelableExtra needs API 33; minSdk is 26.) */
    @Suppress("DEPRECATION")
    private fun openedWith(intent: Intent) {
        val uri: Uri? = when (intent.action) {
            Intent.ACTION_VIEW -> intent.data
            Intent.ACTION_SEND -> intent.getParcelableExtra(Intent.EXTRA_STREAM)
            else -> null
        }
        if (uri != null) import(uri)
    }

    /** Hands a document to the core: its descriptor (read there, off the Java heap) and its
     *  display name. Errors in the file itself appear on the core's banner. */
    private fun import(uri: Uri) {
        val name = displayName(uri) ?: uri.lastPathSegment ?: "model"
        try {
            val pfd = contentResolver.openFileDescriptor(uri, "r")
            if (pfd == null) {
                Toast.makeText(this, getString(R.string.cannot_open, name), Toast.LENGTH_LONG).show()
                return
            }
            render.importFd(name, pfd.detachFd())
        } catch (e: java.io.FileNotFoundException) {
            Toast.makeText(this, getString(R.string.cannot_open, name), Toast.LENGTH_LONG).show()
        } catch (e: SecurityException) {
            Toast.makeText(this, getString(R.string.cannot_open, name), Toast.LENGTH_LONG).show()
        }
    }

    private fun displayName(uri: Uri): String? =
        contentResolver.query(uri, arrayOf(OpenableColumns.DISPLAY_NAME), null, null, null)?.use { c ->
            if (c.moveToFirst()) c.getString(c.getColumnIndex(OpenableColumns.DISPLAY_NAME)) else null
        }

    private fun startCamera() {
        if (camera == null) camera = CameraForwarder(this) { render.engine }.also { it.start(this, wantRear) }
    }

    /** The panel in its natural orientation: the current metrics, turned back by the rotation. */
    private fun panel(): Panel {
        @Suppress("DEPRECATION")
        val display = windowManager.defaultDisplay
        val metrics = DisplayMetrics()
        @Suppress("DEPRECATION")
        display.getRealMetrics(metrics)
        val rotation = display.rotation
        val quarter = rotation == Surface.ROTATION_90 || rotation == Surface.ROTATION_270
        return Panel(
            widthPx = if (quarter) metrics.heightPixels else metrics.widthPixels,
            heightPx = if (quarter) metrics.widthPixels else metrics.heightPixels,
            xdpi = if (quarter) metrics.ydpi else metrics.xdpi,
            ydpi = if (quarter) metrics.xdpi else metrics.ydpi,
            rotation = rotation,
            refreshRateHz = display.refreshRate
        )
    }

    /** Copies the face models from the APK's assets to app storage once; null without them. */
    /** The APK's face models and bundled artifacts are copied out once per install or update
     *  (an update may bring new ones: the copies of the last are removed first). */
    private fun refreshBundledAssets(prefs: SharedPreferences) {
        val stamp = packageManager.getPackageInfo(packageName, 0).lastUpdateTime
        if (prefs.getLong(PREF_ASSETS_STAMP, -1L) == stamp) return
        File(filesDir, "models").deleteRecursively()
        File(filesDir, BUNDLED).deleteRecursively()
        copyAssets(BUNDLED, File(filesDir, BUNDLED))
        prefs.edit().putLong(PREF_ASSETS_STAMP, stamp).apply()
    }

    /** Copies an asset file, or an asset folder with everything in it (the museum's scans). */
    private fun copyAssets(from: String, to: File) {
        val names = assets.list(from) ?: return
        if (names.isEmpty()) {
            to.parentFile?.mkdirs()
            val partial = File(to.path + ".part")
            try {
                assets.open(from).use { input -> partial.outputStream().use { input.copyTo(it) } }
                partial.renameTo(to)
            } catch (e: java.io.IOException) {
                Log.w(TAG, "cannot copy $from", e)
            }
            return
        }
        to.mkdirs()
        for (name in names) copyAssets("$from/$name", File(to, name))
    }

    private fun extractFaceModels(): String? {
        val names = assets.list("models")?.filter { it.endsWith(".onnx") } ?: return null
        if (names.size < 3) return null
        val dir = File(filesDir, "models").apply { mkdirs() }
        for (name in names) {
            val target = File(dir, name)
            if (target.exists()) continue
            val partial = File(dir, "$name.part")
            assets.open("models/$name").use { input -> partial.outputStream().use { input.copyTo(it) } }
            partial.renameTo(target)
        }
        return dir.absolutePath
    }

    private companion object {
        const val TAG = "Phantogram"
        const val PREFS = "phantogram"
        const val PREF_ARTIFACT = "artifact"
        const val PREF_ASSETS_STAMP = "assets_stamp"
        /** The APK's assets folder of bundled artifacts, and its copy in the app's files. */
        const val BUNDLED = "artifacts"
        /** What the document picker offers: glTF binary and JSON, STL, PLY and OBJ (under the types
         *  apps report them as), point clouds as text (.xyz and .pts: reported as plain text, or
         *  as the molecule format that shares the .xyz name), laser scans (.las, .laz; an .e57
         *  comes as octet-stream), USD (.usdz and loose layers, under their IANA types), zip
         *  (Voyager downloads), and octet-stream, as which many providers report a .glb or .stl.
         *  The core recognises each by its bytes. */
        val MODEL_TYPES = arrayOf(
            "model/gltf-binary", "model/gltf+json",
            "model/stl", "model/x.stl-binary", "model/x.stl-ascii", "application/sla", "application/vnd.ms-pki.stl",
            "application/ply", "model/ply", "model/obj",
            "text/plain", "chemical/x-xyz",
            "application/vnd.las", "application/vnd.laszip",
            "model/vnd.usdz+zip", "model/vnd.pixar.usd",
            "application/zip", "application/octet-stream"
        )
    }
}
