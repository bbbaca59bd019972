import java.nio.ByteBuffer;
import java.nio.ByteOrder;
import java.nio.DoubleBuffer;
import java.nio.file.Files;
import java.nio.file.Paths;

/** StrictMathBatch FN IN OUT: StrictMath.FN (exp, cos, pow) of the little-endian doubles in IN
 *  (pairs x, y for pow), written to OUT as little-endian doubles. */
public class StrictMathBatch {
    public static void main(String[] args) throws Exception {
        byte[] in = Files.readAllBytes(Paths.get(args[1]));
        DoubleBuffer d = ByteBuffer.wrap(in).order(ByteOrder.LITTLE_ENDIAN).asDoubleBuffer();
        ByteBuffer out = ByteBuffer.allocate(in.length).order(ByteOrder.LITTLE_ENDIAN);
        while (d.hasRemaining()) {
            double x = d.get();
            switch (args[0]) {
                case "exp": out.putDouble(StrictMath.exp(x)); break;
                case "cos": out.putDouble(StrictMath.cos(x)); break;
                case "pow": out.putDouble(StrictMath.pow(x, d.get())); break;
                default: throw new IllegalArgumentException(args[0]);
            }
        }
        Files.write(Paths.get(args[2]), java.util.Arrays.copyOf(out.array(), out.position()));
    }
}
