import java.io.*;
import java.util.*;

import net.sourceforge.jFuzzyLogic.FunctionBlock;
import net.sourceforge.jFuzzyLogic.rule.Variable;

/**
 * Many oracle runs in one JVM (test-only; the JVM start costs more than a whole system's rows).
 *
 * usage: java -cp ORACLE_JARS:THIS_DIR JflBatch JOBS.txt
 *
 * JOBS.txt: one job per line, "MODEL.fcl<TAB>INPUTS.csv<TAB>OUTPUTS" (OUTPUTS: comma-separated
 * output names, or "-" for every output).  Each job does exactly what the oracle's JflOracle
 * does for "jfl MODEL INPUTS [--outputs OUTPUTS]": it loads the model with JflOracle.loadFirst
 * (the first function block, syntax errors counted) and evaluates the rows in order on that one
 * function block (DEFAULT := NC state carries over).  Output per job: "## job N", then
 * JflOracle's lines: "# LOAD_ERROR ..." or "# syntax_errors=N", the header and one CSV row of
 * %.17g values (nan, ERR:<message>) per input row.  An INPUTS.csv whose header is "*=V" means
 * one evaluation with every input variable set to V.
 */
public class JflBatch {
    public static void main(String[] args) throws Exception {
        PrintStream out = new PrintStream(new BufferedOutputStream(new FileOutputStream(FileDescriptor.out)), false, "UTF-8");
        PrintStream quiet = new PrintStream(new OutputStream() { public void write(int b) {} });
        BufferedReader jobs = new BufferedReader(new FileReader(args[0]));
        String job;
        int n = 0;
        while ((job = jobs.readLine()) != null) {
            if (job.trim().isEmpty()) continue;
            String[] f = job.split("\t");
            out.println("## job " + (n++));
            run(f[0], f[1], f.length > 2 && !f[2].equals("-") ? f[2] : null, out, quiet);
        }
        out.flush();
    }

    static void run(String model, String csv, String outs, PrintStream out, PrintStream quiet) throws Exception {
        PrintStream stdout = System.out, stderr = System.err;
        FunctionBlock fb;
        List<String> names = new ArrayList<String>();
        try {
            System.setOut(quiet);  // jFuzzyLogic prints warnings (values out of range) on stdout
            System.setErr(quiet);
            fb = JflOracle.loadFirst(model, null, names)[0];
        } catch (Throwable e) {
            System.setOut(stdout);
            System.setErr(stderr);
            out.println("# LOAD_ERROR " + e.getClass().getSimpleName() + ": " + String.valueOf(e.getMessage()).replace('\n', ' '));
            return;
        }
        out.println("# syntax_errors=" + JflOracle.syntaxErrors);
        List<String> outNames = new ArrayList<String>();
        if (outs != null) outNames.addAll(Arrays.asList(outs.split(",")));
        else for (Variable v : fb.variablesSorted()) if (v.isOutput()) outNames.add(v.getName());
        out.println(String.join(",", outNames));
        BufferedReader r = new BufferedReader(new FileReader(csv));
        String[] inNames = r.readLine().trim().split(",");
        if (inNames.length == 1 && inNames[0].startsWith("*=")) {
            // one evaluation with every input variable (a variable without defuzzifier) set to a value
            List<String> all = new ArrayList<String>();
            for (Variable v : fb.variablesSorted()) if (!v.isOutput()) all.add(v.getName());
            String value = inNames[0].substring(2);
            r.close();
            StringWriter sw = new StringWriter();
            sw.write(String.join(",", all) + "\n");
            for (int j = 0; j < all.size(); j++) sw.write((j > 0 ? "," : "") + value);
            sw.write(all.isEmpty() ? "-\n" : "\n");
            r = new BufferedReader(new StringReader(sw.toString()));
            inNames = r.readLine().trim().split(",");
            if (all.isEmpty()) { inNames = new String[0]; }
        }
        String line;
        while ((line = r.readLine()) != null) {
            line = line.trim();
            if (line.isEmpty()) continue;
            String[] cells = line.split(",");
            if (inNames.length == 0) cells = new String[0];
            StringBuilder sb = new StringBuilder();
            try {
                for (int j = 0; j < inNames.length; j++) fb.setVariable(inNames[j].trim(), Double.parseDouble(cells[j].trim()));
                fb.evaluate();
                for (int k = 0; k < outNames.size(); k++) {
                    if (k > 0) sb.append(',');
                    Variable v = fb.getVariable(outNames.get(k));
                    sb.append(v == null ? "ERR:no_variable" : JflOracle.fmt(v.getValue()));
                }
            } catch (Throwable e) {
                sb.setLength(0);
                String msg = (e.getClass().getSimpleName() + ":" + String.valueOf(e.getMessage())).replaceAll("[,\\n\\r]", " ");
                for (int k = 0; k < outNames.size(); k++) { if (k > 0) sb.append(','); sb.append("ERR:" + msg); }
            }
            out.println(sb);
        }
        r.close();
        System.setOut(stdout);
        System.setErr(stderr);
    }
}
