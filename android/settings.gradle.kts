// The Android shell of Phantogram. Build with `cargo xtask android` (native libraries for every
// ABI, then this Gradle build); see ../README.md for what is needed and how to install.
pluginManagement {
    repositories {
        google()
        mavenCentral()
        gradlePluginPortal()
    }
}
dependencyResolutionManagement {
    repositoriesMode.set(RepositoriesMode.FAIL_ON_PROJECT_REPOS)
    repositories {
        google()
        mavenCentral()
    }
}
rootProject.name = "Phantogram"
include(":app")
