// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package android.util; public class DisplayMetrics { public int widthPixels, heightPixels; public float xdpi, ydpi, density; }
