import Foundation
import PhantogramCore

/// An error from the core: its status code and message.
public struct PhantogramError: Error, CustomStringConvertible {
    public let status: PgStatus
    public let message: String
    public var description: String { "phantogram error \(status.rawValue): \(message)" }
}

/// Reads the calling thread's last error message (the core keeps one per thread).
func lastError() -> String {
    let needed = pg_last_error(nil, 0)
    var buffer = [CChar](repeating: 0, count: needed)
    _ = pg_last_error(&buffer, needed)
    return String(cString: buffer)
}

@discardableResult
func check(_ status: PgStatus) throws -> PgStatus {
    if status == PG_STATUS_OK || status == PG_STATUS_REJECTED { return status }
    throw PhantogramError(status: status, message: lastError())
}

/// Owns the core's engine handle. Sensor and camera calls may come from any queue; lifecycle and
/// drawing calls from the main thread (where the display link runs).
public final class Engine {
    let handle: OpaquePointer

    /// Opens the GPU device and loads the default artifact (and the face models from the app
    /// bundle's `models` folder when present). Call once, at start.
    public init(panelWidthPx: UInt32, panelHeightPx: UInt32, pixelsPerInch: Float) throws {
        var config = pg_config_default()
        config.panel_width_px = panelWidthPx
        config.panel_height_px = panelHeightPx
        config.xdpi = pixelsPerInch
        config.ydpi = pixelsPerInch
        let faces = Bundle.main.resourceURL?.appendingPathComponent("models").path
        let hasFaces = faces.map { FileManager.default.fileExists(atPath: $0) } ?? false
        // The viewer's calibration (three-finger tap), kept in Application Support.
        let support = try? FileManager.default.url(for: .applicationSupportDirectory, in: .userDomainMask,
                                                   appropriateFor: nil, create: true)
        let calibration = support?.appendingPathComponent("calibration.txt").path
        // Imported artifacts live beside it; the one last on screen comes back.
        let library = support?.appendingPathComponent("artifacts").path
        let bundled = Bundle.main.resourceURL?.appendingPathComponent("artifacts").path
        let saved = UserDefaults.standard.string(forKey: Engine.savedArtifactKey)
        var out: OpaquePointer?
        let status: PgStatus = (hasFaces ? faces! : "").withCString { facesPtr in
            (calibration ?? "").withCString { calibrationPtr in
                (library ?? "").withCString { libraryPtr in
                    (bundled ?? "").withCString { bundledPtr in
                        (saved ?? "").withCString { savedPtr in
                            config.face_models_dir = hasFaces ? facesPtr : nil
                            config.calibration_path = calibration != nil ? calibrationPtr : nil
                            config.library_dir = library != nil ? libraryPtr : nil
                            config.bundled_dir = bundled != nil ? bundledPtr : nil
                            config.artifact = saved != nil ? savedPtr : nil
                            return pg_engine_create(&config, &out)
                        }
                    }
                }
            }
        }
        try check(status)
        guard let engine = out else { throw PhantogramError(status: status, message: "no handle") }
        handle = engine
        // A calibration file that could not be read or applied: the defaults are in use; say why.
        var needed = 0
        if pg_calibration_warning(engine, nil, 0, &needed) == PG_STATUS_OK, needed > 1 {
            var text = [CChar](repeating: 0, count: needed)
            _ = pg_calibration_warning(engine, &text, needed, &needed)
            print("Phantogram: \(String(cString: text))")
        }
    }

    deinit {
        pg_engine_destroy(handle)
    }

    static let savedArtifactKey = "artifact"

    /// Saves the artifact on screen for the next start.
    public func saveCurrentArtifact() {
        let needed = pg_current_artifact(handle, nil, 0)
        guard needed > 1 else { return }
        var text = [CChar](repeating: 0, count: needed)
        _ = pg_current_artifact(handle, &text, needed)
        UserDefaults.standard.set(String(cString: text), forKey: Engine.savedArtifactKey)
    }

    /// Hands a document the user opened to the core (copied there; loaded in the background, the
    /// core's banner shows progress or why it failed).
    public func importArtifact(name: String, data: Data) throws {
        _ = try data.withUnsafeBytes { (raw: UnsafeRawBufferPointer) in
            let bytes = raw.bindMemory(to: UInt8.self)
            return try check(pg_import_artifact(handle, name, bytes.baseAddress, bytes.count))
        }
    }

    /// What the core's screens ask of the app (`pg_take_shell_request`).
    enum ShellRequest {
        /// The document picker for a .glb, .gltf, .stl, .ply, .obj, .xyz, .pts, .las, .laz, .e57, .usdz or .zip.
        case openFile
        /// The system's camera permission request (the core's camera page said why).
        case cameraPermission
        /// The share sheet with a snapshot of the view: the anaglyph, or the stereo pair.
        case share(pair: Bool)
        /// Run the rear camera beside the front one where the device can (the room light is on),
        /// or stop it (off).
        case rearCamera(on: Bool)
    }

    /// The oldest request of the core's screens, or nil; call after each frame.
    func takeShellRequest() -> ShellRequest? {
        var request: Int32 = 0
        guard pg_take_shell_request(handle, &request) == PG_STATUS_OK else { return nil }
        switch request {
        case 1: return .openFile
        case 2: return .cameraPermission
        case 3: return .share(pair: false)
        case 4: return .share(pair: true)
        case 5: return .rearCamera(on: true)
        case 6: return .rearCamera(on: false)
        default: return nil
        }
    }

    /// The view as PNG bytes, without the core's screens over it: the anaglyph, or the
    /// side-by-side stereo pair (`pg_snapshot_png`, asked for its size first).
    func snapshotPng(pair: Bool) throws -> Data {
        let kind: Int32 = pair ? 1 : 0
        var len = 0
        try check(pg_snapshot_png(handle, kind, nil, 0, &len))
        var data = Data(count: len)
        try data.withUnsafeMutableBytes { (bytes: UnsafeMutableRawBufferPointer) in
            let base = bytes.bindMemory(to: UInt8.self).baseAddress
            _ = try check(pg_snapshot_png(handle, kind, base, len, &len))
        }
        return data
    }
}
