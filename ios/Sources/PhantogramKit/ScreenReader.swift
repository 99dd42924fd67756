import UIKit
import PhantogramCore

/// VoiceOver over the core's screens. The core draws its menu, settings and pages into the
/// view's Metal layer, so to UIKit the view is one opaque picture; the core reports what is on
/// it (`pg_accessibility_snapshot`: names, roles, states, rectangles in the layer's pixels) and
/// this makes one `UIAccessibilityElement` per node. Activation and slider steps go back to the
/// core (`pg_accessibility_click` / `pg_accessibility_adjust`), which applies them in its next
/// frame as it would a tap.
///
/// Main thread only (UIKit's accessibility runs there, as does the view's display link).
/// Not compiled on the project's Linux machine (no Xcode): see the README.
final class ScreenReader {
    private weak var view: UIView?
    private let engine: Engine
    private var generation: UInt64 = .max

    init(view: UIView, engine: Engine) {
        self.view = view
        self.engine = engine
    }

    /// After each frame: when the core's nodes changed, rebuild the elements and tell VoiceOver.
    func refreshIfChanged() {
        guard UIAccessibility.isVoiceOverRunning, let view = view else { return }
        var now: UInt64 = 0
        guard pg_accessibility_generation(engine.handle, &now) == PG_STATUS_OK, now != generation else { return }
        var snapshot: OpaquePointer?
        guard pg_accessibility_snapshot(engine.handle, &snapshot, &generation) == PG_STATUS_OK,
              let snap = snapshot else { return }
        defer { pg_access_snapshot_free(snap) }
        let scale = view.contentScaleFactor
        var elements: [Element] = []
        for i in 0..<pg_access_snapshot_len(snap) {
            var node = PgAccessNode()
            guard pg_access_snapshot_node(snap, i, &node) == PG_STATUS_OK, let label = node.label else { continue }
            let element = Element(accessibilityContainer: view, reader: self, id: node.id, flags: node.flags)
            element.accessibilityLabel = String(cString: label)
            if let value = node.value { element.accessibilityValue = String(cString: value) }
            element.accessibilityFrameInContainerSpace = CGRect(
                x: CGFloat(node.left) / scale, y: CGFloat(node.top) / scale,
                width: CGFloat(node.right - node.left) / scale, height: CGFloat(node.bottom - node.top) / scale)
            var traits: UIAccessibilityTraits = []
            switch node.role {
            case 0: traits.insert(.staticText)
            case 1, 2, 3: traits.insert(.button)
            case 4: traits.insert(.adjustable)
            case 5: traits.insert(.image)
            default: break
            }
            if node.flags & 4 != 0, node.flags & 8 != 0 { traits.insert(.selected) }
            if node.flags & 16 != 0 { traits.insert(.notEnabled) }
            element.accessibilityTraits = traits
            elements.append(element)
        }
        view.accessibilityElements = elements
        UIAccessibility.post(notification: .layoutChanged, argument: nil)
    }

    fileprivate func activate(_ id: Int32) -> Bool {
        var acted: UInt8 = 0
        return pg_accessibility_click(engine.handle, id, &acted) == PG_STATUS_OK && acted != 0
    }

    fileprivate func adjust(_ id: Int32, by steps: Int32) {
        var acted: UInt8 = 0
        _ = pg_accessibility_adjust(engine.handle, id, steps, &acted)
    }

    /// One node of the core's screens.
    private final class Element: UIAccessibilityElement {
        private weak var reader: ScreenReader?
        private let id: Int32
        private let flags: UInt32

        init(accessibilityContainer: Any, reader: ScreenReader, id: Int32, flags: UInt32) {
            self.reader = reader
            self.id = id
            self.flags = flags
            super.init(accessibilityContainer: accessibilityContainer)
        }

        override func accessibilityActivate() -> Bool {
            guard flags & 1 != 0 else { return false }
            return reader?.activate(id) ?? false
        }

        override func accessibilityIncrement() { reader?.adjust(id, by: 1) }
        override func accessibilityDecrement() { reader?.adjust(id, by: -1) }
    }
}
