// swift-tools-version:5.9
// The iOS shell of Phantogram as a Swift package: `PhantogramCore` is the Rust core (static
// library + C header + module map in an XCFramework made by `cargo xtask ios` on macOS),
// `PhantogramKit` the thin Swift layer that forwards the Metal layer, Core Motion, the front
// camera, touches and display-link frames to it. The app target (App/, project.yml for
// XcodeGen) only puts a PhantogramView on screen.
import PackageDescription

let package = Package(
    name: "Phantogram",
    platforms: [.iOS(.v15)],
    products: [
        .library(name: "PhantogramKit", targets: ["PhantogramKit"]),
    ],
    targets: [
        .binaryTarget(name: "PhantogramCore", path: "build/PhantogramCore.xcframework"),
        .target(
            name: "PhantogramKit",
            dependencies: ["PhantogramCore"],
            path: "Sources/PhantogramKit",
            linkerSettings: [
                .linkedFramework("Metal"),
                .linkedFramework("QuartzCore"),
                .linkedFramework("CoreMotion"),
                .linkedFramework("AVFoundation"),
                // The core's mesh simplifier (meshoptimizer, in phantogram-detail) is C++.
                .linkedLibrary("c++"),
            ]
        ),
    ]
)
