// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package org.phantogram; public final class R { public static final class string { public static final int app_name = 1; public static final int tilt_only = 2; public static final int cannot_open = 3; public static final int share_title = 4; public static final int cannot_share = 5; } }
