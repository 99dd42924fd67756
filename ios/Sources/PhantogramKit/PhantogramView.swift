import UIKit
import QuartzCore
import UniformTypeIdentifiers
import PhantogramCore

/// The phantogram on screen: a view backed by a `CAMetalLayer` that the core draws into.
///
/// Surface contract (after Filament's UiHelper): in a window → `pg_resume_view`; layout →
/// `pg_resize` in physical pixels (bounds × native scale, so nothing is drawn blurry); out of the
/// window or the app in the background → `pg_suspend` (the GPU device and sensor state stay).
/// Frames come from a `CADisplayLink` on the main run loop, paused in the background.
public final class PhantogramView: UIView, UIDocumentPickerDelegate {
    public override class var layerClass: AnyClass { CAMetalLayer.self }

    private let engine: Engine
    private let motion: MotionSource
    private var camera: CameraSource?
    /// The core asks for the rear camera while the room light is on; kept for the camera's start.
    private var wantRear = false
    private var link: CADisplayLink?
    private var resumed = false
    private lazy var screenReader = ScreenReader(view: self, engine: engine)
    private var observers: [NSObjectProtocol] = []

    public init(engine: Engine) {
        self.engine = engine
        self.motion = MotionSource(engine: engine)
        super.init(frame: .zero)
        isMultipleTouchEnabled = true
        let center = NotificationCenter.default
        observers.append(center.addObserver(forName: UIApplication.didEnterBackgroundNotification,
                                            object: nil, queue: .main) { [weak self] _ in self?.background() })
        observers.append(center.addObserver(forName: UIApplication.willEnterForegroundNotification,
                                            object: nil, queue: .main) { [weak self] _ in self?.foreground() })
        // Dynamic Type: the core's screens follow the user's text size.
        observers.append(center.addObserver(forName: UIContentSizeCategory.didChangeNotification,
                                            object: nil, queue: .main) { [weak self] _ in self?.applyTextScale() })
        applyTextScale()
    }

    /// The user's text size as a ratio to the default body size, for the core's screens.
    private func applyTextScale() {
        let body: CGFloat = 17
        let scale = UIFontMetrics(forTextStyle: .body).scaledValue(for: body) / body
        _ = pg_set_text_scale(engine.handle, Float(scale))
    }

    @available(*, unavailable)
    required init?(coder: NSCoder) { fatalError("PhantogramView is made in code") }

    deinit {
        observers.forEach(NotificationCenter.default.removeObserver)
        link?.invalidate()
        motion.stop()
        camera?.stop()
        pg_suspend(engine.handle)
    }

    private var pixelSize: (UInt32, UInt32) {
        let s = contentScaleFactor
        return (UInt32(max(0, bounds.width * s)), UInt32(max(0, bounds.height * s)))
    }

    public override func didMoveToWindow() {
        super.didMoveToWindow()
        if let window = window {
            contentScaleFactor = window.screen.nativeScale
            (layer as? CAMetalLayer)?.contentsScale = window.screen.nativeScale
            foreground()
            if camera == nil { camera = CameraSource.startIfAllowed(engine: engine, withRear: wantRear) }
        } else {
            background()
        }
    }

    public override func layoutSubviews() {
        super.layoutSubviews()
        let (w, h) = pixelSize
        if resumed { try? check(pg_resize(engine.handle, w, h)) }
    }

    private func foreground() {
        guard window != nil, !resumed else { return }
        let (w, h) = pixelSize
        do {
            try check(pg_resume_view(engine.handle, Unmanaged.passUnretained(self).toOpaque(), w, h))
            resumed = true
        } catch {
            NSLog("phantogram: %@", String(describing: error))
            return
        }
        motion.start()
        let link = CADisplayLink(target: self, selector: #selector(step(_:)))
        // ProMotion screens: ask for their full rate (a phantogram follows the head; every frame
        // sooner is less lag). iOS grants more than 60 Hz only with the app's Info.plist key
        // `CADisableMinimumFrameDurationOnPhone` (set in App/project.yml).
        if #available(iOS 15.0, *) {
            let fastest = Float(UIScreen.main.maximumFramesPerSecond)
            link.preferredFrameRateRange = CAFrameRateRange(minimum: 30, maximum: fastest, preferred: fastest)
        }
        link.add(to: .main, forMode: .common)
        self.link = link
    }

    private func background() {
        engine.saveCurrentArtifact()
        link?.invalidate()
        link = nil
        motion.stop()
        if resumed {
            pg_suspend(engine.handle)
            resumed = false
        }
    }

    @objc private func step(_ link: CADisplayLink) {
        var presented: UInt8 = 0
        // targetTimestamp: when this frame will be on screen (the core predicts the pose to it).
        do { try check(pg_draw(engine.handle, link.targetTimestamp, &presented)) } catch {
            NSLog("phantogram: %@", String(describing: error))
        }
        switch engine.takeShellRequest() {
        case .openFile?: presentDocumentPicker()
        case .cameraPermission?: camera?.requestAccess()
        case .share(let pair)?: presentShareSheet(pair: pair)
        case .rearCamera(let on)?:
            wantRear = on
            camera?.setRear(on)
        case nil: break
        }
        // VoiceOver reads the core's screens as elements of this view.
        screenReader.refreshIfChanged()
    }

    /// The core's menu: the view through the system's share sheet, as a named PNG file.
    private func presentShareSheet(pair: Bool) {
        do {
            let png = try engine.snapshotPng(pair: pair)
            let name = pair ? "phantogram-stereo-pair.png" : "phantogram-anaglyph.png"
            let url = FileManager.default.temporaryDirectory.appendingPathComponent(name)
            try png.write(to: url, options: .atomic)
            let sheet = UIActivityViewController(activityItems: [url], applicationActivities: nil)
            // iPad: the sheet is a popover and needs an anchor.
            sheet.popoverPresentationController?.sourceView = self
            sheet.popoverPresentationController?.sourceRect = CGRect(x: bounds.midX, y: bounds.midY, width: 1, height: 1)
            window?.rootViewController?.present(sheet, animated: true)
        } catch {
            NSLog("phantogram: cannot share: %@", String(describing: error))
        }
    }

    /// The core's menu asked for a file: the system's document browser for glTF, STL, PLY, OBJ,
    /// point clouds as text (.xyz, .pts), laser scans (.las, .laz, .e57), USD (.usdz, .usd, .usda,
    /// .usdc) and zip files.
    private func presentDocumentPicker() {
        var types: [UTType] = [.zip]
        for ext in ["glb", "gltf", "usdz", "usd", "usda", "usdc", "stl", "ply", "obj", "xyz", "pts", "las", "laz", "e57"] {
            if let t = UTType(filenameExtension: ext) { types.append(t) }
        }
        let picker = UIDocumentPickerViewController(forOpeningContentTypes: types, asCopy: true)
        picker.delegate = self
        window?.rootViewController?.present(picker, animated: true)
    }

    public func documentPicker(_ controller: UIDocumentPickerViewController, didPickDocumentsAt urls: [URL]) {
        guard let url = urls.first else { return }
        open(url)
    }

    /// Opens a file given to the app ("Open in", the picker's copy): its bytes go to the core.
    public func open(_ url: URL) {
        let scoped = url.startAccessingSecurityScopedResource()
        defer { if scoped { url.stopAccessingSecurityScopedResource() } }
        do {
            let data = try Data(contentsOf: url, options: .mappedIfSafe)
            try engine.importArtifact(name: url.lastPathComponent, data: data)
        } catch {
            NSLog("phantogram: cannot open %@: %@", url.lastPathComponent, String(describing: error))
        }
    }

    // Touches: one call per touch and phase, physical pixels, Core Motion's clock.
    private func forward(_ touches: Set<UITouch>, phase: Int32) {
        let s = contentScaleFactor
        for touch in touches {
            let p = touch.location(in: self)
            let id = Int32(truncatingIfNeeded: ObjectIdentifier(touch).hashValue)
            pg_touch(engine.handle, phase, id, Float(p.x * s), Float(p.y * s), touch.timestamp, nil)
        }
    }

    public override func touchesBegan(_ touches: Set<UITouch>, with event: UIEvent?) { forward(touches, phase: 0) }
    public override func touchesMoved(_ touches: Set<UITouch>, with event: UIEvent?) { forward(touches, phase: 1) }
    public override func touchesEnded(_ touches: Set<UITouch>, with event: UIEvent?) { forward(touches, phase: 2) }
    public override func touchesCancelled(_ touches: Set<UITouch>, with event: UIEvent?) { forward(touches, phase: 3) }
}
