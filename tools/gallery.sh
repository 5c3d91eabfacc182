#!/usr/bin/env bash
# Render every example into gallery/NAME/ and write gallery/index.html, which
# shows each script beside the pictures it made (open it in a browser).
set -u
frac=${1:-build/frac}
cd "$(dirname "$0")/.."
out=gallery
rm -rf "$out"
mkdir -p "$out"
esc() { sed -e 's/&/\&amp;/g' -e 's/</\&lt;/g' -e 's/>/\&gt;/g'; }
{
    echo '<!doctype html><html><head><meta charset="utf-8"><title>frac gallery</title>'
    echo '<style>body{font-family:sans-serif;background:#111;color:#ddd;margin:2em}'
    echo 'section{display:flex;gap:2em;border-top:1px solid #333;padding:1em 0}'
    echo 'pre{background:#1a1a1a;padding:1em;max-width:50em;overflow:auto;font-size:12px}'
    echo 'img{max-width:420px;image-rendering:pixelated;background:#333;margin:0 .5em .5em 0}'
    echo 'a{color:#8cf}</style></head><body><h1>frac gallery</h1>'
} > "$out/index.html"
for script in examples/*.frac; do
    name=$(basename "$script" .frac)
    mkdir -p "$out/$name"
    if ! "$frac" --quiet -o "$out/$name" "$script" > "$out/$name/stdout.txt" 2> "$out/$name/stderr.txt"; then
        echo "gallery: $script failed (see $out/$name/stderr.txt)" >&2
    fi
    {
        echo "<section><div><h2>$name</h2><pre>"
        esc < "$script"
        echo "</pre></div><div>"
        for f in "$out/$name"/*; do
            b=$(basename "$f")
            case "$b" in
                stdout.txt|stderr.txt) ;;
                *.png) echo "<figure><img src=\"$name/$b\" alt=\"$b\"><figcaption>$b</figcaption></figure>" ;;
                *) echo "<p><a href=\"$name/$b\">$b</a></p>" ;;
            esac
        done
        if [ -s "$out/$name/stdout.txt" ]; then
            echo "<h3>output</h3><pre>"
            esc < "$out/$name/stdout.txt"
            echo "</pre>"
        fi
        echo "</div></section>"
    } >> "$out/index.html"
done
echo '</body></html>' >> "$out/index.html"
echo "wrote $out/index.html"
