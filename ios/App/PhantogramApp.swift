import SwiftUI
import UIKit
import PhantogramKit

/// The app: one full-screen PhantogramView. Everything else is in the core.
@main
struct PhantogramApp: App {
    var body: some Scene {
        WindowGroup {
            PhantogramScreen().ignoresSafeArea().statusBarHidden(true)
                // "Open in" / a shared glTF or zip: handed to the view, which hands it to the core.
                .onOpenURL { url in PhantogramScreen.view?.open(url) }
        }
    }
}

struct PhantogramScreen: UIViewRepresentable {
    /// The one view, for files opened from other apps.
    static weak var view: PhantogramView?

    func makeUIView(context: Context) -> UIView {
        let screen = UIScreen.main
        let size = screen.nativeBounds.size // portrait, physical pixels
        // Points per inch are not published by UIKit; 163 × scale is the iPhone convention
        // (within a few percent of every model; the calibration screens correct the rest).
        let ppi = Float(163.0 * screen.nativeScale)
        do {
            let engine = try Engine(panelWidthPx: UInt32(size.width), panelHeightPx: UInt32(size.height),
                                    pixelsPerInch: ppi)
            let view = PhantogramView(engine: engine)
            PhantogramScreen.view = view
            return view
        } catch {
            let label = UILabel()
            label.numberOfLines = 0
            label.text = "Phantogram could not start: \(error)"
            return label
        }
    }

    func updateUIView(_ uiView: UIView, context: Context) {}
}
